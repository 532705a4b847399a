#include "server/auth/auth_store.hpp"

#include <gtest/gtest.h>
#include <sodium.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "storage/archive/sqlite.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::server {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kStart = 1'700'000'000;
const std::string kPassword = "correct horse battery";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool url_safe(const std::string& s) {
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') return false;
  return true;
}

std::string decode_base64url(const std::string& s) {
  std::string out(s.size(), '\0');
  size_t len = 0;
  EXPECT_EQ(sodium_base642bin(reinterpret_cast<unsigned char*>(out.data()), out.size(), s.data(), s.size(), nullptr,
                              &len, nullptr, sodium_base64_VARIANT_URLSAFE_NO_PADDING),
            0);
  out.resize(len);
  return out;
}

class AuthStoreTest : public ::testing::Test {
 protected:
  void SetUp() override { path_ = bodyscan::testing::temp_dir() + "/accounts.db"; }

  AuthOptions options() {
    AuthOptions o;
    o.opslimit = crypto_pwhash_OPSLIMIT_MIN;
    o.memlimit = crypto_pwhash_MEMLIMIT_MIN;
    o.now = [clock = clock_] { return clock->load(); };
    return o;
  }

  std::unique_ptr<AuthStore> open(AuthOptions o) {
    auto s = AuthStore::open(path_, std::move(o));
    EXPECT_TRUE(s.ok()) << s.status().message();
    return s.ok() ? std::move(*s) : nullptr;
  }
  std::unique_ptr<AuthStore> open() { return open(options()); }

  void advance(int64_t s) { *clock_ += s; }
  int64_t now() const { return clock_->load(); }

  // Everything SQLite has on disk for the store: the database and its WAL.
  std::string disk_bytes() const { return slurp(path_) + slurp(path_ + "-wal") + slurp(path_ + "-shm"); }

  std::string path_;
  std::shared_ptr<std::atomic<int64_t>> clock_ = std::make_shared<std::atomic<int64_t>>(kStart);
};

TEST(RoleTest, NamesRoundTrip) {
  for (Role r : {Role::kOperator, Role::kTailor, Role::kAdmin}) EXPECT_EQ(role_from_string(to_string(r)), r);
  EXPECT_STREQ(to_string(Role::kTailor), "tailor");
  EXPECT_FALSE(role_from_string("Admin"));
  EXPECT_FALSE(role_from_string(""));
}

TEST_F(AuthStoreTest, AddAccountValidatesNamesAndPasswords) {
  auto store = open();
  ASSERT_TRUE(store);
  for (const std::string& bad : {std::string(), std::string(65, 'a'), std::string("a b"), std::string("a/b"),
                                 std::string("j\xc3\xbcrgen"), std::string("x\0y", 3), std::string("<script>")}) {
    auto a = store->add_account(bad, kPassword, Role::kOperator);
    ASSERT_FALSE(a.ok()) << bad;
    EXPECT_EQ(a.status().code(), StatusCode::kInvalidArgument) << bad;
  }
  EXPECT_EQ(store->add_account("anna", "123456789", Role::kOperator).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->add_account("anna", std::string(1025, 'p'), Role::kOperator).status().code(),
            StatusCode::kInvalidArgument);
  // Nine two-byte characters are 18 bytes but still too short; ten are enough.
  std::string nine, ten;
  for (int i = 0; i < 9; ++i) nine += "\xc3\xa4";
  ten = nine + "\xc3\xa4";
  EXPECT_EQ(store->add_account("anna", nine, Role::kOperator).status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(store->add_account("anna", ten, Role::kOperator).ok());

  auto max = store->add_account(std::string(64, 'z'), std::string(1024, 'p'), Role::kTailor);
  ASSERT_TRUE(max.ok()) << max.status().message();
  auto dotted = store->add_account("j.doe_2-b", kPassword, Role::kAdmin);
  ASSERT_TRUE(dotted.ok());
  EXPECT_EQ(dotted->role, Role::kAdmin);
  EXPECT_EQ(dotted->created_at, "2023-11-14T22:13:20Z");

  EXPECT_EQ(store->add_account("anna", kPassword, Role::kAdmin).status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(store->add_account("ANNA", kPassword, Role::kAdmin).status().code(), StatusCode::kFailedPrecondition);

  auto all = store->accounts();
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 3u);
  EXPECT_EQ((*all)[0].username, "anna");
  EXPECT_EQ((*all)[1].username, "j.doe_2-b");
  EXPECT_EQ((*all)[2].role, Role::kTailor);
  EXPECT_EQ(store->account("Anna")->username, "anna");
  EXPECT_EQ(store->account("nobody").status().code(), StatusCode::kNotFound);
}

TEST_F(AuthStoreTest, StoresOnlyArgon2idHashesInAPrivateFile) {
  const std::string secret = "Tr0ub4dor&3-unique-password";
  {
    auto store = open();
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->add_account("anna", secret, Role::kAdmin).ok());
    ASSERT_EQ(store->login("anna", secret, "10.0.0.1").outcome, LoginResult::kOk);
    const std::string bytes = disk_bytes();
    EXPECT_EQ(bytes.find(secret), std::string::npos);
    EXPECT_NE(bytes.find("$argon2id$"), std::string::npos);
  }
  EXPECT_EQ(slurp(path_).find(secret), std::string::npos);

  struct stat st {};
  ASSERT_EQ(::stat(path_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);

  auto db = storage::Database::open(path_);
  ASSERT_TRUE(db.ok());
  auto q = db->prepare("SELECT password_hash FROM accounts WHERE username = 'anna'");
  ASSERT_TRUE(q.ok());
  ASSERT_TRUE(*q->step());
  const std::string hash = q->text(0);
  EXPECT_EQ(hash.rfind("$argon2id$", 0), 0u) << hash;
  EXPECT_EQ(crypto_pwhash_str_verify(hash.c_str(), secret.data(), secret.size()), 0);
}

TEST_F(AuthStoreTest, LoginChecksThePassword) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kTailor).ok());

  const LoginResult ok = store->login("anna", kPassword, "10.0.0.1");
  ASSERT_EQ(ok.outcome, LoginResult::kOk);
  EXPECT_EQ(ok.token.size(), 43u);  // 256 bits, base64url
  EXPECT_TRUE(url_safe(ok.token));
  EXPECT_EQ(decode_base64url(ok.token).size(), 32u);
  EXPECT_EQ(ok.session.username, "anna");
  EXPECT_EQ(ok.session.role, Role::kTailor);
  EXPECT_GE(ok.session.csrf_token.size(), 32u);
  EXPECT_NE(ok.session.csrf_token, ok.token);
  EXPECT_EQ(ok.session.expires_at, kStart + 2 * 3600);

  // The name is matched regardless of case; the session carries its spelling.
  const LoginResult upper = store->login("ANNA", kPassword, "10.0.0.1");
  ASSERT_EQ(upper.outcome, LoginResult::kOk);
  EXPECT_EQ(upper.session.username, "anna");
  EXPECT_NE(upper.token, ok.token);
  EXPECT_NE(upper.session.csrf_token, ok.session.csrf_token);

  const LoginResult wrong = store->login("anna", kPassword + "!", "10.0.0.1");
  EXPECT_EQ(wrong.outcome, LoginResult::kBadCredentials);
  EXPECT_TRUE(wrong.token.empty());
  EXPECT_EQ(store->login("bert", kPassword, "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("", "", "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("anna", std::string(5000, 'x'), "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("not a name", kPassword, "10.0.0.1").outcome, LoginResult::kBadCredentials);
}

TEST_F(AuthStoreTest, SessionLookupAndLogout) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  const LoginResult a = store->login("anna", kPassword, "10.0.0.1");
  const LoginResult b = store->login("anna", kPassword, "10.0.0.2");
  ASSERT_EQ(a.outcome, LoginResult::kOk);
  ASSERT_EQ(b.outcome, LoginResult::kOk);

  auto s = store->session(a.token);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->username, "anna");
  EXPECT_EQ(s->role, Role::kOperator);
  EXPECT_EQ(s->csrf_token, a.session.csrf_token);

  // The role is the account's current one.
  ASSERT_TRUE(store->set_role("anna", Role::kTailor).ok());
  EXPECT_EQ(store->session(a.token)->role, Role::kTailor);

  store->logout(a.token);
  EXPECT_FALSE(store->session(a.token));
  EXPECT_TRUE(store->session(b.token));  // other sessions stay
  store->logout(a.token);                // twice is harmless

  ASSERT_TRUE(store->end_sessions("anna").ok());
  EXPECT_FALSE(store->session(b.token));
}

TEST_F(AuthStoreTest, SessionsExpireWhenIdle) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  const LoginResult r = store->login("anna", kPassword, "10.0.0.1");
  ASSERT_EQ(r.outcome, LoginResult::kOk);

  // Use keeps it alive past the idle limit ...
  for (int i = 0; i < 3; ++i) {
    advance(2 * 3600 - 10);
    auto s = store->session(r.token);
    ASSERT_TRUE(s) << i;
    EXPECT_EQ(s->expires_at, now() + 2 * 3600);
  }
  // ... silence does not.
  advance(2 * 3600);
  EXPECT_FALSE(store->session(r.token));
  advance(-2 * 3600);
  EXPECT_FALSE(store->session(r.token)) << "an expired session is gone, not dormant";
}

TEST_F(AuthStoreTest, SessionsExpireAfterTheirLifetimeHoweverUsed) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  const LoginResult r = store->login("anna", kPassword, "10.0.0.1");
  ASSERT_EQ(r.outcome, LoginResult::kOk);
  for (int64_t t = 0; t + 3600 < 12 * 3600; t += 3600) {
    advance(3600);
    ASSERT_TRUE(store->session(r.token)) << t;
  }
  advance(3599);  // 12 h minus a second after login
  auto last = store->session(r.token);
  ASSERT_TRUE(last);
  EXPECT_EQ(last->expires_at, kStart + 12 * 3600);
  advance(1);
  EXPECT_FALSE(store->session(r.token));
}

TEST_F(AuthStoreTest, ExpiredSessionsArePurgedAtLogin) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 5; ++i) ASSERT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
  advance(2 * 3600);
  ASSERT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
  auto db = storage::Database::open(path_);
  ASSERT_TRUE(db.ok());
  auto q = db->prepare("SELECT COUNT(*) FROM sessions");
  ASSERT_TRUE(q.ok());
  ASSERT_TRUE(*q->step());
  EXPECT_EQ(q->integer(0), 1);
}

TEST_F(AuthStoreTest, LoginUpgradesHashesMadeAtALowerCost) {
  {
    auto store = open();
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  }
  auto stored_hash = [&] {
    auto db = storage::Database::open(path_);
    auto q = db->prepare("SELECT password_hash FROM accounts");
    EXPECT_TRUE(*q->step());
    return q->text(0);
  };
  const std::string before = stored_hash();
  AuthOptions o = options();
  o.opslimit = crypto_pwhash_OPSLIMIT_MIN + 1;
  auto store = open(o);
  ASSERT_TRUE(store);
  EXPECT_EQ(store->login("anna", "wrong password", "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(stored_hash(), before);
  ASSERT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
  const std::string after = stored_hash();
  EXPECT_NE(after, before);
  EXPECT_EQ(crypto_pwhash_str_needs_rehash(after.c_str(), o.opslimit, o.memlimit), 0);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
}

TEST_F(AuthStoreTest, ReopeningKeepsAccountsAndSessionsButNoRawTokens) {
  LoginResult r;
  {
    auto store = open();
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->add_account("anna", kPassword, Role::kAdmin).ok());
    r = store->login("anna", kPassword, "10.0.0.1");
    ASSERT_EQ(r.outcome, LoginResult::kOk);
    const std::string bytes = disk_bytes();
    EXPECT_EQ(bytes.find(r.token), std::string::npos);
    EXPECT_EQ(bytes.find(decode_base64url(r.token)), std::string::npos);
  }
  const std::string bytes = disk_bytes();
  EXPECT_EQ(bytes.find(r.token), std::string::npos);
  EXPECT_EQ(bytes.find(decode_base64url(r.token)), std::string::npos);

  advance(600);
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->has_admin());
  auto s = store->session(r.token);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->username, "anna");
  EXPECT_EQ(s->csrf_token, r.session.csrf_token);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
}

TEST_F(AuthStoreTest, RateLimitsGuessesAtOneAccountFromOneAddress) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(store->login("anna", "wrong password", "10.0.0.1").outcome, LoginResult::kBadCredentials);
    advance(10);
  }
  // t = 50 s after the first failure: refused there, even with the right password.
  LoginResult r = store->login("Anna", kPassword, "10.0.0.1");
  EXPECT_EQ(r.outcome, LoginResult::kRateLimited);
  EXPECT_EQ(r.retry_after_s, 250);
  EXPECT_TRUE(r.token.empty());
  // Anna at her own tablet is not locked out by guesses from another address.
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.2").outcome, LoginResult::kOk);
  // Refusals do not count: the first failure ages out on time.
  advance(249);
  r = store->login("anna", kPassword, "10.0.0.1");
  EXPECT_EQ(r.outcome, LoginResult::kRateLimited);
  EXPECT_EQ(r.retry_after_s, 1);
  advance(1);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
  // Unknown users are limited the same way (no hint that they do not exist).
  for (int i = 0; i < 5; ++i) store->login("ghost", "wrong password", "10.3.0.1");
  EXPECT_EQ(store->login("ghost", "wrong password", "10.3.0.1").outcome, LoginResult::kRateLimited);
  // The whole window later everything is allowed again.
  advance(300);
  EXPECT_EQ(store->login("ghost", "wrong password", "10.3.0.1").outcome, LoginResult::kBadCredentials);
}

TEST_F(AuthStoreTest, RateLimitsGuessesFromOneAddress) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 20; ++i)
    EXPECT_EQ(store->login("user" + std::to_string(i), "wrong password", "192.0.2.7").outcome,
              LoginResult::kBadCredentials);
  advance(100);
  LoginResult r = store->login("anna", kPassword, "192.0.2.7");
  EXPECT_EQ(r.outcome, LoginResult::kRateLimited);
  EXPECT_EQ(r.retry_after_s, 200);
  EXPECT_EQ(store->login("anna", kPassword, "192.0.2.8").outcome,
            LoginResult::kOk);  // another address
  advance(200);
  EXPECT_EQ(store->login("anna", kPassword, "192.0.2.7").outcome, LoginResult::kOk);
}

// Guessing at one account from many addresses (each under its own limit) puts
// the brake on that account: every address gets one failure. An address that
// failed at nothing still logs in with the right password.
TEST_F(AuthStoreTest, GuessesAtOneAccountFromManyAddressesAreBraked) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  ASSERT_TRUE(store->add_account("bert", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 20; ++i)
    EXPECT_EQ(store->login("anna", "wrong password", "10.9.0." + std::to_string(i)).outcome,
              LoginResult::kBadCredentials);
  // Every guessing address is refused for anna after one failure ...
  EXPECT_EQ(store->login("anna", "another guess", "10.9.0.3").outcome, LoginResult::kRateLimited);
  EXPECT_EQ(store->login("anna", kPassword, "10.9.0.3").outcome, LoginResult::kRateLimited);
  // ... a new one gets one failure ...
  EXPECT_EQ(store->login("anna", "wrong password", "10.9.1.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("anna", "wrong password", "10.9.1.1").outcome, LoginResult::kRateLimited);
  // ... and anna, from where she failed at nothing, gets in; bert is untouched.
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.5").outcome, LoginResult::kOk);
  EXPECT_EQ(store->login("bert", "one typo here", "10.9.0.3").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("bert", kPassword, "10.9.0.3").outcome, LoginResult::kOk);
}

// Guessing all over (many accounts, many addresses) puts the brake on
// everything: one failure per address and account.
TEST_F(AuthStoreTest, SprayingPutsTheBrakeOnEveryAccount) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 100; ++i)
    EXPECT_EQ(
        store->login("user" + std::to_string(i % 50), "wrong password", "10.8." + std::to_string(i) + ".1").outcome,
        LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("anna", "one typo here", "10.0.0.5").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.5").outcome, LoginResult::kRateLimited);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.6").outcome, LoginResult::kOk);
  advance(301);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.5").outcome, LoginResult::kOk);
}

TEST_F(AuthStoreTest, SuccessClearsTheFailuresAtThatAddress) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 4; ++i) store->login("anna", "typo typo typo", "10.0.0.1");
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(store->login("anna", "typo typo typo", "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
}

TEST_F(AuthStoreTest, RateLimitCanBeTurnedOff) {
  AuthOptions o = options();
  o.max_failures = 0;
  auto store = open(o);
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  for (int i = 0; i < 20; ++i) store->login("anna", "wrong password", "10.0.0.1");
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kOk);
}

TEST_F(AuthStoreTest, SetPasswordEndsSessions) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  ASSERT_TRUE(store->add_account("bert", kPassword, Role::kOperator).ok());
  const LoginResult a = store->login("anna", kPassword, "10.0.0.1");
  const LoginResult b = store->login("bert", kPassword, "10.0.0.1");
  ASSERT_EQ(a.outcome, LoginResult::kOk);

  EXPECT_EQ(store->set_password("anna", "short").code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(store->session(a.token));
  EXPECT_EQ(store->set_password("nobody", "a new password").code(), StatusCode::kNotFound);

  ASSERT_TRUE(store->set_password("anna", "a new password").ok());
  EXPECT_FALSE(store->session(a.token));
  EXPECT_TRUE(store->session(b.token));
  EXPECT_EQ(store->login("anna", kPassword, "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->login("anna", "a new password", "10.0.0.1").outcome, LoginResult::kOk);
}

TEST_F(AuthStoreTest, ProtectsTheLastAdmin) {
  auto store = open();
  ASSERT_TRUE(store);
  EXPECT_FALSE(store->has_admin());
  ASSERT_TRUE(store->add_account("root", kPassword, Role::kAdmin).ok());
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  EXPECT_TRUE(store->has_admin());

  EXPECT_EQ(store->set_role("root", Role::kTailor).code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(store->delete_account("root").code(), StatusCode::kFailedPrecondition);
  EXPECT_TRUE(store->set_role("root", Role::kAdmin).ok());  // no change is fine
  EXPECT_EQ(store->set_role("nobody", Role::kAdmin).code(), StatusCode::kNotFound);
  EXPECT_EQ(store->delete_account("nobody").code(), StatusCode::kNotFound);

  ASSERT_TRUE(store->set_role("anna", Role::kAdmin).ok());
  const LoginResult r = store->login("root", kPassword, "10.0.0.1");
  ASSERT_EQ(r.outcome, LoginResult::kOk);
  ASSERT_TRUE(store->set_role("root", Role::kOperator).ok());
  EXPECT_EQ(store->session(r.token)->role, Role::kOperator);
  EXPECT_EQ(store->set_role("anna", Role::kOperator).code(), StatusCode::kFailedPrecondition);

  ASSERT_TRUE(store->delete_account("root").ok());
  EXPECT_FALSE(store->session(r.token));
  EXPECT_EQ(store->login("root", kPassword, "10.0.0.1").outcome, LoginResult::kBadCredentials);
  EXPECT_EQ(store->delete_account("anna").code(), StatusCode::kFailedPrecondition);
  EXPECT_TRUE(store->has_admin());
  // A name that was deleted can be taken again, without the old sessions.
  ASSERT_TRUE(store->add_account("root", "another password", Role::kOperator).ok());
  EXPECT_FALSE(store->session(r.token));
}

// A PIN staff read out: six digits, kept hashed with the token as the key; five
// wrong tries in the link's life withdraw it.
TEST_F(AuthStoreTest, APinProtectsALinkAndWrongTriesWithdrawIt) {
  auto store = open();
  ASSERT_TRUE(store);
  ShareOptions o;
  o.pin = true;
  auto made = store->create_share("s_1", {}, 3600, "anna", o);
  ASSERT_TRUE(made.ok());
  ASSERT_EQ(made->pin.size(), 6u);
  EXPECT_TRUE(std::all_of(made->pin.begin(), made->pin.end(), [](char c) { return c >= '0' && c <= '9'; }));
  EXPECT_TRUE(store->share_by_token(made->token)->pin);
  EXPECT_FALSE(store->share_by_token(store->create_share("s_1", {}, 3600, "anna")->token)->pin);
  const std::string wrong = made->pin == "123456" ? "654321" : "123456";
  int left = -1;
  EXPECT_EQ(*store->check_share_pin(made->token, wrong, &left), PinAnswer::kWrong);
  EXPECT_EQ(left, 4);
  EXPECT_EQ(*store->check_share_pin(made->token, made->pin, &left), PinAnswer::kRight);
  EXPECT_EQ(*store->check_share_pin(made->token, "", &left), PinAnswer::kWrong);
  EXPECT_EQ(*store->check_share_pin(made->token, wrong, &left), PinAnswer::kWrong);
  EXPECT_EQ(*store->check_share_pin(made->token, wrong, &left), PinAnswer::kWrong);
  EXPECT_EQ(left, 1);
  EXPECT_EQ(*store->check_share_pin(made->token, wrong, &left), PinAnswer::kWithdrawn);
  EXPECT_FALSE(store->share_by_token(made->token));
  EXPECT_EQ(store->check_share_pin(made->token, made->pin).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store->check_share_pin("not-a-token", made->pin).status().code(), StatusCode::kNotFound);
}

// A database from before the head could be left out: its links showed the head,
// and keep doing so after the column is added.
TEST_F(AuthStoreTest, LinksMadeBeforeTheHeadCouldBeLeftOutKeepShowingIt) {
  std::string token;
  {
    auto store = open();
    ASSERT_TRUE(store);
    token = store->create_share("s_1", {}, 3600, "anna")->token;
  }
  {
    auto db = storage::Database::open(path_);
    ASSERT_TRUE(db.ok());
    ASSERT_TRUE(db->exec("ALTER TABLE shares DROP COLUMN include_head").ok());
  }
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->share_by_token(token));
  EXPECT_TRUE(store->share_by_token(token)->include_head);
  EXPECT_FALSE(store->share_by_token(store->create_share("s_1", {}, 3600, "anna")->token)->include_head);
}

TEST_F(AuthStoreTest, ShareLinks) {
  auto store = open();
  ASSERT_TRUE(store);
  auto made = store->create_share("s_1", {"waist_girth", "Hüftumfang"}, 7 * 86400, "anna");
  ASSERT_TRUE(made.ok()) << made.status().message();
  const NewShare share = *made;
  EXPECT_EQ(share.token.size(), 22u);  // 128 bits, base64url
  EXPECT_TRUE(url_safe(share.token));
  EXPECT_EQ(decode_base64url(share.token).size(), 16u);
  EXPECT_EQ(share.link.id.size(), 19u);
  EXPECT_EQ(share.link.id.rfind("sh_", 0), 0u);
  EXPECT_EQ(share.link.expires_at, kStart + 7 * 86400);
  EXPECT_EQ(share.link.created_by, "anna");
  EXPECT_EQ(share.link.created_at, "2023-11-14T22:13:20Z");
  EXPECT_EQ(disk_bytes().find(share.token), std::string::npos);

  auto found = store->share_by_token(share.token);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->id, share.link.id);
  EXPECT_EQ(found->scan_id, "s_1");
  EXPECT_EQ(found->measurements, (std::vector<std::string>{"waist_girth", "Hüftumfang"}));
  EXPECT_FALSE(found->revoked);
  EXPECT_FALSE(found->include_head) << "the head is left out unless staff include it";
  ShareOptions with_head;
  with_head.include_head = true;
  auto headed = store->create_share("s_9", {}, 60, "anna", with_head);
  ASSERT_TRUE(headed.ok());
  EXPECT_TRUE(store->share_by_token(headed->token)->include_head);
  EXPECT_TRUE(store->shares("s_9")->back().include_head);

  // Tokens and ids are unique.
  std::set<std::string> tokens{share.token}, ids{share.link.id};
  for (int i = 0; i < 200; ++i) {
    auto s = store->create_share("s_2", {}, 60, "bert");
    ASSERT_TRUE(s.ok());
    tokens.insert(s->token);
    ids.insert(s->link.id);
  }
  EXPECT_EQ(tokens.size(), 201u);
  EXPECT_EQ(ids.size(), 201u);

  // Expiry.
  auto short_lived = store->create_share("s_1", {"chest_girth"}, 3600, "anna");
  ASSERT_TRUE(short_lived.ok());
  advance(3599);
  EXPECT_TRUE(store->share_by_token(short_lived->token));
  advance(1);
  EXPECT_FALSE(store->share_by_token(short_lived->token));
  EXPECT_TRUE(store->share_by_token(share.token));

  // Revocation.
  ASSERT_TRUE(store->revoke_share(share.link.id).ok());
  EXPECT_FALSE(store->share_by_token(share.token));
  EXPECT_EQ(store->revoke_share("sh_0000000000000000").code(), StatusCode::kNotFound);

  // Listing keeps revoked and expired links, oldest first.
  auto listed = store->shares("s_1");
  ASSERT_TRUE(listed.ok());
  ASSERT_EQ(listed->size(), 2u);
  EXPECT_EQ((*listed)[0].id, share.link.id);
  EXPECT_TRUE((*listed)[0].revoked);
  EXPECT_EQ((*listed)[1].measurements, std::vector<std::string>{"chest_girth"});
  EXPECT_FALSE((*listed)[1].revoked);
  EXPECT_EQ(store->shares("s_2")->size(), 200u);
  EXPECT_TRUE(store->shares("none")->empty());

  // Erasing a scan erases its links.
  auto other = store->create_share("s_3", {"inseam"}, 86400, "anna");
  ASSERT_TRUE(other.ok());
  ASSERT_TRUE(store->delete_shares_of_scan("s_1").ok());
  EXPECT_TRUE(store->shares("s_1")->empty());
  EXPECT_FALSE(store->share_by_token(short_lived->token));
  EXPECT_TRUE(store->share_by_token(other->token));
  EXPECT_TRUE(store->delete_shares_of_scan("never").ok());
}

TEST_F(AuthStoreTest, CreateShareValidatesInput) {
  auto store = open();
  ASSERT_TRUE(store);
  EXPECT_EQ(store->create_share("s_1", {"waist"}, 0, "anna").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->create_share("s_1", {"waist"}, -5, "anna").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->create_share("s_1", {"waist"}, 365 * 86400 + 1, "anna").status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_TRUE(store->create_share("s_1", {"waist"}, 365 * 86400, "anna").ok());
  EXPECT_EQ(store->create_share("", {"waist"}, 60, "anna").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->create_share("s_1", {""}, 60, "anna").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->create_share("s_1", {"bad\xff"}, 60, "anna").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->create_share("s_1", {"line\nbreak"}, 60, "anna").status().code(), StatusCode::kInvalidArgument);
}

TEST_F(AuthStoreTest, MalformedTokensAreJustUnknown) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  const LoginResult r = store->login("anna", kPassword, "10.0.0.1");
  ASSERT_EQ(r.outcome, LoginResult::kOk);
  auto share = store->create_share("s_1", {"waist"}, 60, "anna");
  ASSERT_TRUE(share.ok());

  std::string non_ascii = r.token;
  non_ascii.replace(0, 2, "\xc3\xa4");
  const std::vector<std::string> bad = {
      "",
      std::string(1 << 20, 'A'),
      non_ascii,
      std::string(43, '\0'),
      r.token.substr(0, 42),
      r.token + "A",
      r.token + "=",
      std::string(43, 'A'),
      "' OR 1=1 --",
      share->token.substr(0, 21),
      share->token + "AA",
      std::string(22, '/'),
      "%" + share->token.substr(1),
  };
  for (const auto& t : bad) {
    EXPECT_FALSE(store->session(t)) << t.size();
    EXPECT_FALSE(store->share_by_token(t)) << t.size();
    store->logout(t);
  }
  // A share token is not a session token and vice versa.
  EXPECT_FALSE(store->session(share->token));
  EXPECT_FALSE(store->share_by_token(r.token));
  EXPECT_TRUE(store->session(r.token));
  EXPECT_TRUE(store->share_by_token(share->token));
}

TEST_F(AuthStoreTest, ConcurrentLoginsAndLookups) {
  AuthOptions o = options();
  o.max_failures = 1000;
  auto store = open(o);
  ASSERT_TRUE(store);
  constexpr int kThreads = 8;
  for (int i = 0; i < kThreads; ++i)
    ASSERT_TRUE(store->add_account("user" + std::to_string(i), kPassword, Role::kOperator).ok());

  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&, i] {
      const std::string name = "user" + std::to_string(i);
      const std::string addr = "10.0.0." + std::to_string(i);
      for (int round = 0; round < 10; ++round) {
        const LoginResult r = store->login(name, kPassword, addr);
        if (r.outcome != LoginResult::kOk) {
          ++failures;
          continue;
        }
        for (int k = 0; k < 20; ++k) {
          auto s = store->session(r.token);
          if (!s || s->username != name) ++failures;
        }
        if (store->login(name, "wrong password", addr).outcome != LoginResult::kBadCredentials) ++failures;
        auto share = store->create_share("s_" + std::to_string(i), {"waist"}, 60, name);
        if (!share.ok() || !store->share_by_token(share->token)) ++failures;
        store->logout(r.token);
        if (store->session(r.token)) ++failures;
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(store->shares("s_0")->size(), 10u);
}

TEST_F(AuthStoreTest, ParallelGuessesCannotOutrunTheLimit) {
  auto store = open();
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->add_account("anna", kPassword, Role::kOperator).ok());
  std::atomic<int> bad{0}, limited{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 16; ++i)
    threads.emplace_back([&, i] {
      const LoginResult r = store->login("anna", "guess " + std::to_string(i) + " wrong", "10.0.0.1");
      (r.outcome == LoginResult::kRateLimited ? limited : bad)++;
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(bad.load(), 5);
  EXPECT_EQ(limited.load(), 11);
}

TEST_F(AuthStoreTest, RefusesBadOptions) {
  AuthOptions o = options();
  o.session_idle_s = 0;
  EXPECT_EQ(AuthStore::open(path_, o).status().code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(AuthStore::open(bodyscan::testing::temp_dir() + "/missing/dir/accounts.db", options()).ok());
}

}  // namespace
}  // namespace bodyscan::server
