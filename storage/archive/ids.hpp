// How the archive and the server name things: random hex ids and UTC timestamps.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace bodyscan::storage {

// 2 * bytes lowercase hex digits from libsodium's generator (sodium_init() first).
std::string random_hex(size_t bytes);

// "2026-11-22T10:15:00Z".
std::string iso8601_utc(int64_t unix_seconds);

}  // namespace bodyscan::storage
