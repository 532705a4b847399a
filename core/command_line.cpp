#include "core/command_line.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>

namespace bodyscan {

std::optional<double> parse_double(std::string_view text) {
  const std::string s(text);
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(s.c_str(), &end);
  if (*end != '\0' || errno == ERANGE || !std::isfinite(x)) return std::nullopt;
  return x;
}

std::optional<long long> parse_integer(std::string_view text) {
  const std::string s(text);
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(s.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE) return std::nullopt;
  return x;
}

std::optional<std::vector<double>> parse_number_list(std::string_view text, std::size_t count) {
  std::vector<double> v;
  while (true) {
    const std::size_t comma = text.find(',');
    const auto x = parse_double(text.substr(0, comma));
    if (!x) return std::nullopt;
    v.push_back(*x);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  if (count != 0 && v.size() != count) return std::nullopt;
  return v;
}

CommandLine::ValueParser integer_between(long long lo, long long hi, std::function<void(long long)> store) {
  return [lo, hi, store = std::move(store)](const std::string& v) -> std::string {
    const auto x = parse_integer(v);
    if (!x || *x < lo || *x > hi)
      return "expects a number from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" + v + "'";
    store(*x);
    return "";
  };
}

namespace {

template <typename Int>
CommandLine::ValueParser integer_into(Int* out) {
  return [out](const std::string& v) -> std::string {
    const auto x = parse_integer(v);
    if (!x || *x < static_cast<long long>(std::numeric_limits<Int>::min()) ||
        (*x > 0 && static_cast<unsigned long long>(*x) > std::numeric_limits<Int>::max()))
      return "expects an integer, got '" + v + "'";
    *out = static_cast<Int>(*x);
    return "";
  };
}

std::string expects_number(const std::string& v) { return "expects a number, got '" + v + "'"; }

}  // namespace

CommandLine::CommandLine(std::string program, std::string usage)
    : program_(std::move(program)), usage_(std::move(usage)) {}

void CommandLine::add(std::string_view names, bool takes_value, std::function<void()> set_flag, ValueParser parse) {
  Option o;
  while (true) {
    const std::size_t bar = names.find('|');
    o.names.emplace_back(names.substr(0, bar));
    if (bar == std::string_view::npos) break;
    names.remove_prefix(bar + 1);
  }
  o.takes_value = takes_value;
  o.set_flag = std::move(set_flag);
  o.parse = std::move(parse);
  options_.push_back(std::move(o));
}

void CommandLine::flag(std::string_view names, bool* out) {
  add(
      names, false, [out] { *out = true; }, nullptr);
}

void CommandLine::option(std::string_view names, std::string* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    *out = v;
    return std::string();
  });
}

void CommandLine::option(std::string_view names, std::optional<std::string>* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    *out = v;
    return std::string();
  });
}

void CommandLine::option(std::string_view names, double* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    const auto x = parse_double(v);
    if (!x) return expects_number(v);
    *out = *x;
    return std::string();
  });
}

void CommandLine::option(std::string_view names, std::optional<double>* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    const auto x = parse_double(v);
    if (!x) return expects_number(v);
    *out = *x;
    return std::string();
  });
}

void CommandLine::option(std::string_view names, float* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    const auto x = parse_double(v);
    if (!x || std::abs(*x) > std::numeric_limits<float>::max()) return expects_number(v);
    *out = static_cast<float>(*x);
    return std::string();
  });
}

void CommandLine::option(std::string_view names, int* out) { add(names, true, nullptr, integer_into(out)); }

void CommandLine::option(std::string_view names, std::optional<int>* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    int x = 0;
    std::string error = integer_into(&x)(v);
    if (error.empty()) *out = x;
    return error;
  });
}

void CommandLine::option(std::string_view names, std::uint64_t* out) {
  add(names, true, nullptr, [out](const std::string& v) -> std::string {
    if (v.empty() || v[0] < '0' || v[0] > '9') return "expects a whole number, got '" + v + "'";
    char* end = nullptr;
    errno = 0;
    const unsigned long long x = std::strtoull(v.c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE) return "expects a whole number, got '" + v + "'";
    *out = x;
    return "";
  });
}

void CommandLine::option(std::string_view names, std::vector<std::string>* out) {
  add(names, true, nullptr, [out](const std::string& v) {
    out->push_back(v);
    return std::string();
  });
}

void CommandLine::option(std::string_view names, ValueParser parse) { add(names, true, nullptr, std::move(parse)); }

void CommandLine::positional(std::string name, std::string* out, bool required) {
  positionals_.push_back({std::move(name), out, nullptr, required});
}

void CommandLine::rest(std::string name, std::vector<std::string>* out) {
  positionals_.push_back({std::move(name), nullptr, out, false});
}

const CommandLine::Option* CommandLine::find(std::string_view name) const {
  for (const Option& o : options_)
    for (const std::string& n : o.names)
      if (n == name) return &o;
  return nullptr;
}

int CommandLine::fail(const std::string& message) const {
  std::fprintf(stderr, "%s: %s\n", program_.c_str(), message.c_str());
  std::fputs(usage_.c_str(), stderr);
  return 2;
}

std::optional<int> CommandLine::parse(int argc, char** argv) {
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  return parse(args);
}

std::optional<int> CommandLine::parse_option(const std::vector<std::string>& args, std::size_t* i) const {
  const std::string& a = args[*i];
  const std::size_t eq = a.find('=');
  const std::string name = a.substr(0, eq);
  const Option* o = find(name);
  if (!o) return fail("unknown option '" + name + "'");
  if (!o->takes_value) {
    if (eq != std::string::npos) return fail(name + " takes no value");
    o->set_flag();
    return std::nullopt;
  }
  std::string value;
  if (eq != std::string::npos) {
    value = a.substr(eq + 1);
  } else {
    if (*i + 1 >= args.size()) return fail(name + " needs a value");
    value = args[++*i];
  }
  if (std::string error = o->parse(value); !error.empty()) return fail(name + " " + error);
  return std::nullopt;
}

std::optional<int> CommandLine::parse(const std::vector<std::string>& args) {
  std::size_t next_positional = 0;
  bool options_ended = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool looks_like_option = !options_ended && a.size() > 1 && a[0] == '-';
    if (looks_like_option && a == "--") {
      options_ended = true;
    } else if (looks_like_option && (a == "-h" || a == "--help")) {
      std::fputs(usage_.c_str(), stdout);
      return 0;
    } else if (looks_like_option) {
      if (const auto exit = parse_option(args, &i)) return exit;
    } else if (next_positional >= positionals_.size()) {
      return fail("unexpected argument '" + a + "'");
    } else if (Positional& p = positionals_[next_positional]; p.rest) {
      p.rest->push_back(a);
    } else {
      *p.out = a;
      ++next_positional;
    }
  }
  for (std::size_t k = next_positional; k < positionals_.size(); ++k)
    if (positionals_[k].required) return fail("missing " + positionals_[k].name);
  return std::nullopt;
}

}  // namespace bodyscan
