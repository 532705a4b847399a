// PLY reading and writing after Greg Turk, "The PLY Polygon File Format" (1994),
// the format's only specification (paulbourke.net/dataformats/ply/).
//
// Reading works on the whole file in memory: the header is parsed into element and
// property descriptions, then each element is read in file order through a cursor
// (binary: memcpy + byte swap; ASCII: std::from_chars on one line per record). Every
// element's declared count is checked against the bytes left before anything is
// allocated for it, so storage is always bounded by a small multiple of the file size.
#include "recon/io/ply.hpp"
#include "recon/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <system_error>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>

namespace bodyscan {

namespace {

// ---------------------------------------------------------------------------
// Scalar types

enum class Scalar : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct ScalarInfo {
  const char* name;
  size_t size;
  bool integer;
  double min;
  double max;
};

constexpr ScalarInfo kScalarInfo[] = {
    {"char", 1, true, -128.0, 127.0},
    {"uchar", 1, true, 0.0, 255.0},
    {"short", 2, true, -32768.0, 32767.0},
    {"ushort", 2, true, 0.0, 65535.0},
    {"int", 4, true, -2147483648.0, 2147483647.0},
    {"uint", 4, true, 0.0, 4294967295.0},
    {"float", 4, false, -std::numeric_limits<double>::max(), std::numeric_limits<double>::max()},
    {"double", 8, false, -std::numeric_limits<double>::max(), std::numeric_limits<double>::max()},
};

const ScalarInfo& info(Scalar s) { return kScalarInfo[static_cast<int>(s)]; }

bool parse_scalar_name(std::string_view name, Scalar* out) {
  // The 1994 names and the sized aliases later writers (VTK, Open3D, PCL) use.
  static constexpr std::pair<std::string_view, Scalar> kNames[] = {
      {"char", Scalar::kInt8},       {"int8", Scalar::kInt8},       {"uchar", Scalar::kUint8},
      {"uint8", Scalar::kUint8},     {"short", Scalar::kInt16},     {"int16", Scalar::kInt16},
      {"ushort", Scalar::kUint16},   {"uint16", Scalar::kUint16},   {"int", Scalar::kInt32},
      {"int32", Scalar::kInt32},     {"uint", Scalar::kUint32},     {"uint32", Scalar::kUint32},
      {"float", Scalar::kFloat32},   {"float32", Scalar::kFloat32}, {"double", Scalar::kFloat64},
      {"float64", Scalar::kFloat64},
  };
  for (const auto& [n, s] : kNames) {
    if (n == name) {
      *out = s;
      return true;
    }
  }
  return false;
}

template <typename U>
U byte_swap(U u) {
  if constexpr (sizeof(U) == 2) return static_cast<U>(__builtin_bswap16(u));
  if constexpr (sizeof(U) == 4) return __builtin_bswap32(u);
  if constexpr (sizeof(U) == 8) return __builtin_bswap64(u);
}

template <typename T>
T load(const char* p, bool swap) {
  T value;
  if constexpr (sizeof(T) == 1) {
    std::memcpy(&value, p, 1);
  } else {
    using U = std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>;
    U bits;
    std::memcpy(&bits, p, sizeof(U));
    if (swap) bits = byte_swap(bits);
    std::memcpy(&value, &bits, sizeof(U));
  }
  return value;
}

// Every PLY scalar fits a double exactly (the widest integer is 32 bits).
double load_scalar(const char* p, Scalar type, bool swap) {
  switch (type) {
    case Scalar::kInt8: return load<int8_t>(p, swap);
    case Scalar::kUint8: return load<uint8_t>(p, swap);
    case Scalar::kInt16: return load<int16_t>(p, swap);
    case Scalar::kUint16: return load<uint16_t>(p, swap);
    case Scalar::kInt32: return load<int32_t>(p, swap);
    case Scalar::kUint32: return load<uint32_t>(p, swap);
    case Scalar::kFloat32: return load<float>(p, swap);
    case Scalar::kFloat64: return load<double>(p, swap);
  }
  return 0.0;
}

// ---------------------------------------------------------------------------
// Message helpers

// A token from the file, printable and short, for error messages.
std::string quoted(std::string_view s) {
  constexpr size_t kMax = 32;
  std::string out = "'";
  for (size_t i = 0; i < s.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7f && c != '\'') {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  if (s.size() > kMax) out += "...";
  return out + "'";
}

std::string number_text(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  if (v == std::trunc(v) && std::fabs(v) < 1e15) {
    auto r = std::to_chars(buf, buf + sizeof buf, static_cast<long long>(v));
    return std::string(buf, r.ptr);
  }
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string errno_text(int error) { return std::generic_category().message(error); }

// ---------------------------------------------------------------------------
// Header

enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  Scalar type = Scalar::kFloat32;  // the value type, or a list's item type
  bool is_list = false;
  Scalar count_type = Scalar::kUint8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  int line = 0;  // header line, for messages
  std::vector<PlyProperty> properties;

  const PlyProperty* find(std::string_view property) const {
    for (const PlyProperty& p : properties) {
      if (p.name == property) return &p;
    }
    return nullptr;
  }
  bool has_lists() const {
    for (const PlyProperty& p : properties) {
      if (p.is_list) return true;
    }
    return false;
  }
};

struct PlyHeader {
  Encoding encoding = Encoding::kAscii;
  std::vector<PlyElement> elements;
  size_t data_offset = 0;  // first byte after the end_header line
  int data_line = 0;       // line number of that byte
};

void split_tokens(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  size_t i = 0;
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) tokens->push_back(line.substr(start, i - start));
  }
}

// Lines a header may have, comments included. Real files declare a few elements
// with at most some dozens of properties; the cap turns a runaway or hostile header
// into a clear error instead of a long parse.
constexpr int kMaxHeaderLines = 10000;

// Linear in the header's length: duplicate element and property names are found
// through hash sets of views into `bytes`.
StatusOr<PlyHeader> parse_header(std::string_view bytes) {
  if (bytes.empty()) return invalid_argument("empty file; a PLY file starts with the line 'ply'");
  size_t pos;
  if (bytes.starts_with("ply\n")) {
    pos = 4;
  } else if (bytes.starts_with("ply\r\n")) {
    pos = 5;
  } else {
    return invalid_argument("not a PLY file: the first line must be 'ply', the file starts with " +
                            quoted(bytes.substr(0, 16)));
  }

  PlyHeader header;
  bool have_format = false;
  int line_no = 1;
  std::vector<std::string_view> tokens;
  std::unordered_map<std::string_view, int> element_lines;  // name -> header line
  std::unordered_set<std::string_view> property_names;      // of the last element
  auto at_line = [&](const std::string& what) {
    return invalid_argument("header line " + std::to_string(line_no) + ": " + what);
  };
  while (true) {
    if (pos >= bytes.size()) {
      return invalid_argument("the header has no end_header line (the file ends after line " + std::to_string(line_no) +
                              ")");
    }
    size_t end = bytes.find('\n', pos);
    const bool last_line = end == std::string_view::npos;
    if (last_line) end = bytes.size();
    std::string_view line = bytes.substr(pos, end - pos);
    pos = last_line ? end : end + 1;
    ++line_no;
    if (line_no > kMaxHeaderLines) {
      return at_line("no end_header within " + std::to_string(kMaxHeaderLines) +
                     " lines: the header is longer than any real PLY file's");
    }
    split_tokens(line, &tokens);
    if (tokens.empty()) continue;
    const std::string_view keyword = tokens[0];

    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      if (tokens.size() != 1) return at_line("unexpected text after end_header");
      break;
    }
    if (last_line) {
      return invalid_argument("the header has no end_header line (the file ends after line " + std::to_string(line_no) +
                              ")");
    }
    if (keyword == "format") {
      if (have_format) return at_line("a second format line");
      if (tokens.size() != 3) return at_line("expected 'format <encoding> 1.0'");
      if (tokens[1] == "ascii") {
        header.encoding = Encoding::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.encoding = Encoding::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        header.encoding = Encoding::kBinaryBigEndian;
      } else {
        return at_line("unsupported format " + quoted(tokens[1]) +
                       "; expected ascii, binary_little_endian or binary_big_endian");
      }
      if (tokens[2] != "1.0" && tokens[2] != "1") {
        return at_line("unsupported PLY version " + quoted(tokens[2]) + "; expected 1.0");
      }
      have_format = true;
    } else if (keyword == "element") {
      if (tokens.size() != 3) return at_line("expected 'element <name> <count>'");
      PlyElement element;
      element.name = std::string(tokens[1]);
      element.line = line_no;
      const std::string_view count = tokens[2];
      auto r = std::from_chars(count.data(), count.data() + count.size(), element.count);
      if (r.ec != std::errc() || r.ptr != count.data() + count.size()) {
        return at_line("element " + quoted(tokens[1]) + " count " + quoted(count) + " is not a non-negative integer");
      }
      const auto [first, added] = element_lines.emplace(tokens[1], line_no);
      if (!added) {
        return at_line("element " + quoted(element.name) + " is declared twice (also on line " +
                       std::to_string(first->second) + ")");
      }
      header.elements.push_back(std::move(element));
      property_names.clear();
    } else if (keyword == "property") {
      if (header.elements.empty()) return at_line("a property before any element");
      PlyProperty property;
      if (tokens.size() >= 2 && tokens[1] == "list") {
        if (tokens.size() != 5) {
          return at_line("expected 'property list <count type> <item type> <name>'");
        }
        property.is_list = true;
        if (!parse_scalar_name(tokens[2], &property.count_type)) {
          return at_line("unknown list count type " + quoted(tokens[2]));
        }
        if (!info(property.count_type).integer) {
          return at_line("list count type " + quoted(tokens[2]) + " is not an integer type");
        }
        if (!parse_scalar_name(tokens[3], &property.type)) {
          return at_line("unknown list item type " + quoted(tokens[3]));
        }
        property.name = std::string(tokens[4]);
      } else {
        if (tokens.size() != 3) return at_line("expected 'property <type> <name>'");
        if (!parse_scalar_name(tokens[1], &property.type)) {
          return at_line("unknown property type " + quoted(tokens[1]));
        }
        property.name = std::string(tokens[2]);
      }
      PlyElement& element = header.elements.back();
      if (!property_names.insert(tokens.back()).second) {
        return at_line("element " + quoted(element.name) + " has two properties named " + quoted(property.name));
      }
      element.properties.push_back(std::move(property));
    } else {
      return at_line("unknown header keyword " + quoted(keyword) +
                     "; expected format, element, property, comment, obj_info or end_header"
                     " (is end_header missing?)");
    }
  }
  if (!have_format) return invalid_argument("the header has no format line");
  header.data_offset = pos;
  header.data_line = line_no + 1;
  return header;
}

// ---------------------------------------------------------------------------
// Cursors: one value at a time from binary or ASCII data, bounds-checked. On
// failure they return false and leave the reason in error().

class BinaryCursor {
 public:
  BinaryCursor(std::string_view bytes, size_t pos, bool swap)
      : data_(bytes.data()), size_(bytes.size()), pos_(pos), swap_(swap) {}

  size_t remaining() const { return size_ - pos_; }
  size_t offset() const { return pos_; }
  const char* data() const { return data_; }
  bool swap() const { return swap_; }
  void advance(size_t n) { pos_ += n; }  // the caller checked n <= remaining()
  const std::string& error() const { return error_; }
  std::string where() const { return "at offset " + std::to_string(value_start_); }

  void begin_record() {}
  bool end_record() { return true; }

  bool scalar(Scalar type, double* value) {
    const size_t n = info(type).size;
    if (remaining() < n) return truncated(n);
    *value = load_scalar(data_ + pos_, type, swap_);
    value_start_ = pos_;
    pos_ += n;
    return true;
  }

  // Reads a list's count and checks that its items fit in the file.
  bool list_count(const PlyProperty& p, uint64_t* count) {
    double n = 0.0;
    if (!scalar(p.count_type, &n)) return false;
    if (n < 0) {
      error_ = "negative list count " + number_text(n) + " " + where();
      return false;
    }
    // The count type is at most 32 bits, so count * 8 cannot overflow.
    *count = static_cast<uint64_t>(n);
    const size_t item = info(p.type).size;
    if (*count > remaining() / item) {
      error_ = "truncated: a list of " + std::to_string(*count) + " " + info(p.type).name + " needs " +
               std::to_string(*count * item) + " bytes at offset " + std::to_string(pos_) + ", file has " +
               std::to_string(size_) + " bytes";
      return false;
    }
    return true;
  }

  bool skip_list(const PlyProperty& p, uint64_t count) {
    pos_ += count * info(p.type).size;  // list_count checked it fits
    return true;
  }

 private:
  bool truncated(size_t needed) {
    error_ = "truncated: needs " + std::to_string(needed) + " bytes at offset " + std::to_string(pos_) + ", file has " +
             std::to_string(size_) + " bytes";
    return false;
  }

  const char* data_;
  size_t size_;
  size_t pos_;
  bool swap_;
  size_t value_start_ = 0;
  std::string error_;
};

// ASCII data: one record per line (the specification's layout), values separated by
// spaces or tabs. Blank lines between records are tolerated.
class AsciiCursor {
 public:
  AsciiCursor(std::string_view text, size_t pos, int line) : text_(text), pos_(pos), line_(line) {}

  size_t remaining() const { return text_.size() - pos_; }
  size_t offset() const { return pos_; }
  const std::string& error() const { return error_; }
  std::string where() const { return "on line " + std::to_string(line_); }

  void begin_record() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (!is_blank(c)) {
        break;
      }
      ++pos_;
    }
  }

  bool end_record() {
    skip_blanks();
    if (pos_ == text_.size() || text_[pos_] == '\n') return true;
    error_ = "unexpected extra value " + quoted(peek_token()) + " " + where() + " after the last property";
    return false;
  }

  bool scalar(Scalar type, double* value) {
    std::string_view token;
    if (!next_token(&token)) return false;
    return parse(token, type, value);
  }

  bool list_count(const PlyProperty& p, uint64_t* count) {
    double n = 0.0;
    if (!scalar(p.count_type, &n)) return false;
    if (n < 0) {
      error_ = "negative list count " + number_text(n) + " " + where();
      return false;
    }
    *count = static_cast<uint64_t>(n);
    // Each item needs a separator and at least one character.
    if (*count > remaining() / 2) {
      error_ = "truncated: a list of " + std::to_string(*count) + " values " + where() + " cannot fit in the " +
               std::to_string(remaining()) + " bytes left in the file";
      return false;
    }
    return true;
  }

  bool skip_list(const PlyProperty& p, uint64_t count) {
    double ignored;
    for (uint64_t i = 0; i < count; ++i) {
      if (!scalar(p.type, &ignored)) return false;
    }
    return true;
  }

 private:
  static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
  void skip_blanks() {
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
  }
  std::string_view peek_token() const {
    size_t end = pos_;
    while (end < text_.size() && !is_blank(text_[end]) && text_[end] != '\n') ++end;
    return text_.substr(pos_, end - pos_);
  }

  bool next_token(std::string_view* token) {
    skip_blanks();
    if (pos_ == text_.size()) {
      error_ = "unexpected end of file " + where();
      return false;
    }
    if (text_[pos_] == '\n') {
      error_ = "line " + std::to_string(line_) + " ends before all values were read";
      return false;
    }
    *token = peek_token();
    pos_ += token->size();
    return true;
  }

  bool parse(std::string_view token, Scalar type, double* value) {
    const char* begin = token.data();
    const char* end = begin + token.size();
    if (begin != end && *begin == '+' && end - begin > 1 && begin[1] != '-' && begin[1] != '+') {
      ++begin;  // from_chars does not take a leading '+'; some writers emit one
    }
    const ScalarInfo& t = info(type);
    double v = 0.0;
    bool ok = false;
    if (t.integer) {
      long long i;
      auto r = std::from_chars(begin, end, i);
      if (r.ec == std::errc() && r.ptr == end) {
        v = static_cast<double>(i);
        ok = true;
      }
    }
    if (!ok) {
      auto r = std::from_chars(begin, end, v);
      if (r.ptr == end && r.ec == std::errc::result_out_of_range) {
        // from_chars reports underflow as out of range too; strtod tells the two
        // apart (a tiny value becomes 0 or subnormal, a huge one becomes inf).
        const std::string copy(begin, end);
        v = std::strtod(copy.c_str(), nullptr);
        if (!std::isfinite(v)) {
          error_ = quoted(token) + " " + where() + " is out of range";
          return false;
        }
        ok = true;
      } else {
        ok = r.ec == std::errc() && r.ptr == end;
      }
      if (!ok) {
        error_ = quoted(token) + " " + where() + " is not a number";
        return false;
      }
      if (t.integer && v != std::trunc(v)) {
        error_ = quoted(token) + " " + where() + " is not an integer (the type is " + t.name + ")";
        return false;
      }
    }
    if (t.integer && (v < t.min || v > t.max)) {
      error_ = quoted(token) + " " + where() + " does not fit the property's type " + t.name;
      return false;
    }
    *value = v;
    return true;
  }

  std::string_view text_;
  size_t pos_;
  int line_;
  std::string error_;
};

// ---------------------------------------------------------------------------
// Element reading

// Where one property's values go: the element's record i writes f[i * stride] or
// n[i * stride]; face index lists go to the triangle list.
struct Slot {
  enum Kind : uint8_t { kSkip, kFloat, kInt, kCorners };
  Kind kind = kSkip;
  float* f = nullptr;
  int32_t* n = nullptr;
  size_t stride = 1;
};

struct FaceSink {
  std::vector<Triangle>* triangles = nullptr;
  std::vector<uint32_t> corners;
  uint64_t num_vertices = 0;
};

std::string record_label(const PlyElement& e, uint64_t i) {
  return e.name + " " + std::to_string(i) + " of " + std::to_string(e.count);
}

Status record_error(const PlyElement& e, uint64_t i, const PlyProperty& p, const std::string& what) {
  return invalid_argument(record_label(e, i) + ", property " + quoted(p.name) + ": " + what);
}

// Stores a value, refusing what the attribute cannot hold: a NaN or infinite
// coordinate would poison every later stage, and a double outside float range or a
// non-integer id would be undefined behaviour to convert.
bool store(const Slot& slot, uint64_t i, double v, std::string* why) {
  switch (slot.kind) {
    case Slot::kFloat:
      if (std::isnan(v)) {
        *why = "NaN";
        return false;
      }
      if (!(std::fabs(v) <= std::numeric_limits<float>::max())) {
        *why = std::isinf(v) ? "infinite value" : "value " + number_text(v) + " is outside float range";
        return false;
      }
      slot.f[i * slot.stride] = static_cast<float>(v);
      return true;
    case Slot::kInt:
      if (!(v >= -2147483648.0 && v <= 2147483647.0) || v != std::trunc(v)) {
        *why = "value " + number_text(v) + " is not a 32-bit integer";
        return false;
      }
      slot.n[i * slot.stride] = static_cast<int32_t>(v);
      return true;
    case Slot::kSkip:
    case Slot::kCorners: return true;
  }
  return true;
}

template <typename Cursor>
Status read_records(Cursor& cursor, const PlyElement& e, const std::vector<Slot>& slots, FaceSink* faces) {
  std::string why;
  for (uint64_t i = 0; i < e.count; ++i) {
    cursor.begin_record();
    for (size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      const Slot& slot = slots[k];
      if (!p.is_list) {
        double v = 0.0;
        if (!cursor.scalar(p.type, &v)) return record_error(e, i, p, cursor.error());
        if (!store(slot, i, v, &why)) return record_error(e, i, p, why + " " + cursor.where());
        continue;
      }
      uint64_t count;
      if (!cursor.list_count(p, &count)) return record_error(e, i, p, cursor.error());
      if (slot.kind != Slot::kCorners) {
        if (!cursor.skip_list(p, count)) return record_error(e, i, p, cursor.error());
        continue;
      }
      if (count < 3) {
        return record_error(
            e, i, p,
            "a face needs at least 3 corners, this one has " + std::to_string(count) + " (" + cursor.where() + ")");
      }
      faces->corners.resize(count);  // list_count bounded it by the bytes left
      for (uint64_t j = 0; j < count; ++j) {
        double v = 0.0;
        if (!cursor.scalar(p.type, &v)) return record_error(e, i, p, cursor.error());
        // Item types are integers of at most 32 bits (checked with the header), so v
        // is an exact integer and, once in range, fits uint32_t.
        if (!(v >= 0.0 && v < static_cast<double>(faces->num_vertices))) {
          return record_error(e, i, p,
                              "vertex index " + number_text(v) + " " + cursor.where() +
                                  " is out of range: the file has " + std::to_string(faces->num_vertices) +
                                  " vertices");
        }
        faces->corners[j] = static_cast<uint32_t>(v);
      }
      // Fan triangulation: exact for the convex quads and polygons writers emit.
      const auto& c = faces->corners;
      for (size_t j = 1; j + 1 < c.size(); ++j) faces->triangles->push_back({c[0], c[j], c[j + 1]});
    }
    if (!cursor.end_record()) return invalid_argument(record_label(e, i) + ": " + cursor.error());
  }
  return Status::Ok();
}

// Fixed-size binary elements (no lists), the bulk of every scan file: all records
// share one layout, so each property is converted column by column over blocks of
// records that stay in cache, with its type and byte order fixed at compile time.
// Returns the index of the first value the slot refuses (see store), or count.
template <typename T, bool kSwap>
uint64_t convert_column(const char* src, size_t record_size, uint64_t first, uint64_t count, const Slot& slot) {
  if (slot.kind == Slot::kFloat) {
    float* dst = slot.f + first * slot.stride;
    for (uint64_t i = 0; i < count; ++i) {
      const T v = load<T>(src + i * record_size, kSwap);
      if constexpr (std::is_floating_point_v<T>) {
        if (!(std::fabs(v) <= std::numeric_limits<float>::max())) return i;  // NaN, inf, range
      }
      dst[i * slot.stride] = static_cast<float>(v);
    }
  } else {
    assert(slot.kind == Slot::kInt);
    int32_t* dst = slot.n + first * slot.stride;
    for (uint64_t i = 0; i < count; ++i) {
      const T v = load<T>(src + i * record_size, kSwap);
      if constexpr (std::is_floating_point_v<T>) {
        const double d = v;
        if (!(d >= -2147483648.0 && d <= 2147483647.0) || d != std::trunc(d)) return i;
      } else if constexpr (std::is_same_v<T, uint32_t>) {
        if (v > static_cast<uint32_t>(std::numeric_limits<int32_t>::max())) return i;
      }
      dst[i * slot.stride] = static_cast<int32_t>(v);
    }
  }
  return count;
}

using ColumnFn = uint64_t (*)(const char*, size_t, uint64_t, uint64_t, const Slot&);

template <bool kSwap>
ColumnFn column_fn(Scalar type) {
  switch (type) {
    case Scalar::kInt8: return &convert_column<int8_t, kSwap>;
    case Scalar::kUint8: return &convert_column<uint8_t, kSwap>;
    case Scalar::kInt16: return &convert_column<int16_t, kSwap>;
    case Scalar::kUint16: return &convert_column<uint16_t, kSwap>;
    case Scalar::kInt32: return &convert_column<int32_t, kSwap>;
    case Scalar::kUint32: return &convert_column<uint32_t, kSwap>;
    case Scalar::kFloat32: return &convert_column<float, kSwap>;
    case Scalar::kFloat64: return &convert_column<double, kSwap>;
  }
  return nullptr;
}

// Reads a fixed-size element whose count check_count_fits has already checked.
Status read_fixed_binary(BinaryCursor& cursor, const PlyElement& e, const std::vector<Slot>& slots) {
  struct Column {
    size_t property;
    size_t offset;  // within the record
    ColumnFn convert;
  };
  std::vector<Column> columns;
  size_t record_size = 0;
  for (size_t k = 0; k < e.properties.size(); ++k) {
    const Scalar type = e.properties[k].type;
    if (slots[k].kind != Slot::kSkip) {
      columns.push_back({k, record_size, cursor.swap() ? column_fn<true>(type) : column_fn<false>(type)});
    }
    record_size += info(type).size;
  }
  assert(e.count <= cursor.remaining() / record_size);
  const char* records = cursor.data() + cursor.offset();
  constexpr uint64_t kBlock = 2048;
  for (uint64_t first = 0; first < e.count; first += kBlock) {
    const uint64_t n = std::min(kBlock, e.count - first);
    const char* block = records + first * record_size;
    // Report the first refused value in file order, as record-by-record reading would.
    uint64_t bad = n;
    const Column* bad_column = nullptr;
    for (const Column& c : columns) {
      const uint64_t i = c.convert(block + c.offset, record_size, first, n, slots[c.property]);
      if (i < bad) {
        bad = i;
        bad_column = &c;
      }
    }
    if (bad_column != nullptr) {
      const PlyProperty& p = e.properties[bad_column->property];
      const size_t offset = cursor.offset() + (first + bad) * record_size + bad_column->offset;
      std::string why;
      store(slots[bad_column->property], first + bad, load_scalar(cursor.data() + offset, p.type, cursor.swap()), &why);
      return record_error(e, first + bad, p, why + " at offset " + std::to_string(offset));
    }
  }
  cursor.advance(static_cast<size_t>(e.count) * record_size);
  return Status::Ok();
}

// The fewest bytes one record can take, so a declared count can be checked against
// the bytes left before anything is allocated for it.
size_t min_record_bytes(const PlyElement& e, bool ascii, const PlyProperty* corners) {
  size_t bytes = 0;
  size_t values = 0;
  for (const PlyProperty& p : e.properties) {
    // A face list must hold at least 3 indices, any other list may be empty.
    const size_t items = &p == corners ? 3 : 0;
    if (p.is_list) {
      bytes += info(p.count_type).size + items * info(p.type).size;
      values += 1 + items;
    } else {
      bytes += info(p.type).size;
      values += 1;
    }
  }
  // ASCII: each value is at least one character plus one separator (space or the
  // line break), except the file's very last value.
  return ascii ? (values == 0 ? 0 : 2 * values - 1) : bytes;
}

template <typename Cursor>
Status check_count_fits(const Cursor& cursor, const PlyElement& e, size_t min_bytes, bool binary, bool fixed_size) {
  if (e.count == 0 || min_bytes == 0 || e.count <= cursor.remaining() / min_bytes) {
    return Status::Ok();
  }
  const size_t file_size = cursor.offset() + cursor.remaining();
  if (binary && fixed_size) {
    // Every record has the same size: name the first one that is cut off.
    const uint64_t first_missing = cursor.remaining() / min_bytes;
    return invalid_argument("truncated: " + record_label(e, first_missing) + " needs " + std::to_string(min_bytes) +
                            " bytes at offset " + std::to_string(cursor.offset() + first_missing * min_bytes) +
                            ", file has " + std::to_string(file_size) + " bytes");
  }
  return invalid_argument("truncated: the header declares " + std::to_string(e.count) + " " + e.name +
                          " records of at least " + std::to_string(min_bytes) + " bytes each, but only " +
                          std::to_string(cursor.remaining()) + " bytes are left at offset " +
                          std::to_string(cursor.offset()) + " (file has " + std::to_string(file_size) + " bytes)");
}

// ---------------------------------------------------------------------------
// What the reader takes from the vertex, face and camera elements.

enum class VertexField { kOther, kX, kY, kZ, kNx, kNy, kNz, kIntensity, kConfidence, kCamera, kLaser, kFrame };

VertexField vertex_field(std::string_view name) {
  static constexpr std::pair<std::string_view, VertexField> kFields[] = {
      {"x", VertexField::kX},
      {"y", VertexField::kY},
      {"z", VertexField::kZ},
      {"nx", VertexField::kNx},
      {"ny", VertexField::kNy},
      {"nz", VertexField::kNz},
      {"intensity", VertexField::kIntensity},
      {"confidence", VertexField::kConfidence},
      {"camera", VertexField::kCamera},
      {"laser", VertexField::kLaser},
      {"frame", VertexField::kFrame},
  };
  for (const auto& [n, f] : kFields) {
    if (n == name) return f;
  }
  return VertexField::kOther;
}

Status check_vertex_element(const PlyElement& v) {
  for (const char* name : {"x", "y", "z"}) {
    if (v.find(name) == nullptr) {
      return invalid_argument("element 'vertex' (header line " + std::to_string(v.line) + ") has no property '" + name +
                              "'");
    }
  }
  for (const PlyProperty& p : v.properties) {
    if (p.is_list && vertex_field(p.name) != VertexField::kOther) {
      return invalid_argument("vertex property " + quoted(p.name) + " is a list; it must be a single value per vertex");
    }
  }
  const int normals = (v.find("nx") != nullptr) + (v.find("ny") != nullptr) + (v.find("nz") != nullptr);
  if (normals != 0 && normals != 3) {
    return invalid_argument("element 'vertex' has only some of the normal properties nx, ny, nz");
  }
  return Status::Ok();
}

// The face element's index list, or null when it has none.
const PlyProperty* face_corners(const PlyElement& f) {
  const PlyProperty* p = f.find("vertex_indices");
  return p != nullptr ? p : f.find("vertex_index");
}

Status check_face_element(const PlyElement& f) {
  const PlyProperty* corners = face_corners(f);
  if (corners == nullptr) {
    if (f.count == 0) return Status::Ok();
    return invalid_argument("element 'face' (header line " + std::to_string(f.line) + ") has no 'vertex_indices' list");
  }
  if (!corners->is_list) {
    return invalid_argument("face property " + quoted(corners->name) +
                            " must be a list of vertex indices, not a single value");
  }
  if (!info(corners->type).integer) {
    return invalid_argument("face property " + quoted(corners->name) + " has item type " + info(corners->type).name +
                            "; vertex indices must be integers");
  }
  return Status::Ok();
}

// Only a `camera` element with scalar x, y, z holds camera centres; other writers
// (e.g. VCG's view_px, ...) use the name differently, and those are skipped.
bool holds_camera_centres(const PlyElement& c) {
  for (const char* name : {"x", "y", "z"}) {
    const PlyProperty* p = c.find(name);
    if (p == nullptr || p->is_list) return false;
  }
  return true;
}

template <typename Cursor>
Status read_body(Cursor& cursor, const PlyHeader& header, PlyData* out) {
  constexpr bool binary = std::is_same_v<Cursor, BinaryCursor>;
  const PlyElement* vertex = nullptr;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex") vertex = &e;
  }
  if (vertex == nullptr) return invalid_argument("the header declares no 'vertex' element");
  RETURN_IF_ERROR(check_vertex_element(*vertex));
  for (const PlyElement& e : header.elements) {
    if (e.name == "face") RETURN_IF_ERROR(check_face_element(e));
  }

  PointCloud& cloud = out->cloud;
  FaceSink faces;
  faces.triangles = &out->triangles;
  faces.num_vertices = vertex->count;
  std::vector<Slot> slots;
  for (const PlyElement& e : header.elements) {
    slots.assign(e.properties.size(), Slot{});
    const bool is_vertex = &e == vertex;
    const bool is_face = e.name == "face";
    const bool is_camera = e.name == "camera" && holds_camera_centres(e);
    const PlyProperty* corners = is_face ? face_corners(e) : nullptr;
    if (e.count == 0) continue;
    if (e.properties.empty()) continue;  // records of zero bytes: nothing to read
    // Storage sized by the count (vertices, camera centres) is only allocated once the
    // count is known to fit the bytes left. Other elements are read record by record,
    // each taking at least one byte, so a lying count just runs into the precise
    // "truncated" error; fixed-size binary records can report that error up front.
    const size_t min_bytes = min_record_bytes(e, !binary, corners);
    if (is_vertex || is_camera || (binary && !e.has_lists())) {
      RETURN_IF_ERROR(check_count_fits(cursor, e, min_bytes, binary, !e.has_lists()));
    }
    const size_t n = static_cast<size_t>(std::min<uint64_t>(e.count, cursor.remaining() / min_bytes));
    auto float_slot = [](float* base, size_t stride) { return Slot{Slot::kFloat, base, nullptr, stride}; };
    auto int_slot = [](int32_t* base) { return Slot{Slot::kInt, nullptr, base, 1}; };
    if (is_vertex) {
      cloud.positions.resize(n);
      if (e.find("nx") != nullptr) cloud.normals.resize(n);
      if (e.find("intensity") != nullptr) cloud.intensity.resize(n);
      if (e.find("confidence") != nullptr) cloud.confidence.resize(n);
      if (e.find("camera") != nullptr) cloud.camera.resize(n, kUnknownSource);
      if (e.find("laser") != nullptr) cloud.laser.resize(n, kUnknownSource);
      if (e.find("frame") != nullptr) cloud.frame.resize(n, kUnknownSource);
      float* xyz = cloud.positions.front().data();
      float* nxyz = cloud.normals.empty() ? nullptr : cloud.normals.front().data();
      static_assert(sizeof(Vec3f) == 3 * sizeof(float));
      for (size_t k = 0; k < e.properties.size(); ++k) {
        switch (vertex_field(e.properties[k].name)) {
          case VertexField::kX: slots[k] = float_slot(xyz + 0, 3); break;
          case VertexField::kY: slots[k] = float_slot(xyz + 1, 3); break;
          case VertexField::kZ: slots[k] = float_slot(xyz + 2, 3); break;
          case VertexField::kNx: slots[k] = float_slot(nxyz + 0, 3); break;
          case VertexField::kNy: slots[k] = float_slot(nxyz + 1, 3); break;
          case VertexField::kNz: slots[k] = float_slot(nxyz + 2, 3); break;
          case VertexField::kIntensity: slots[k] = float_slot(cloud.intensity.data(), 1); break;
          case VertexField::kConfidence: slots[k] = float_slot(cloud.confidence.data(), 1); break;
          case VertexField::kCamera: slots[k] = int_slot(cloud.camera.data()); break;
          case VertexField::kLaser: slots[k] = int_slot(cloud.laser.data()); break;
          case VertexField::kFrame: slots[k] = int_slot(cloud.frame.data()); break;
          case VertexField::kOther: break;
        }
      }
    } else if (is_camera) {
      cloud.camera_centres.resize(n);
      float* xyz = cloud.camera_centres.front().data();
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const std::string& name = e.properties[k].name;
        if (name == "x") slots[k] = float_slot(xyz + 0, 3);
        if (name == "y") slots[k] = float_slot(xyz + 1, 3);
        if (name == "z") slots[k] = float_slot(xyz + 2, 3);
      }
    } else if (is_face && corners != nullptr) {
      // At least one triangle per face that can fit; polygons add more as they are read.
      out->triangles.reserve(out->triangles.size() + n);
      slots[static_cast<size_t>(corners - e.properties.data())].kind = Slot::kCorners;
    }
    if constexpr (binary) {
      if (!e.has_lists()) {
        RETURN_IF_ERROR(read_fixed_binary(cursor, e, slots));
        continue;
      }
    }
    RETURN_IF_ERROR(read_records(cursor, e, slots, &faces));
  }

  // Ids index the centres when the file has them (PointCloud::is_consistent).
  const auto num_centres = static_cast<int64_t>(cloud.camera_centres.size());
  for (size_t i = 0; i < cloud.camera.size(); ++i) {
    const int32_t id = cloud.camera[i];
    if (id == kUnknownSource) continue;
    if (id < 0 || (num_centres > 0 && id >= num_centres)) {
      return invalid_argument("vertex " + std::to_string(i) + " has camera id " + std::to_string(id) +
                              ", but the file has " + std::to_string(num_centres) +
                              " camera centres (ids must be -1 for unknown or index them)");
    }
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------
// Writing

constexpr bool kNativeLittleEndian = std::endian::native == std::endian::little;

template <typename T>
void put(char*& p, T v) {
  if constexpr (!kNativeLittleEndian && sizeof(T) > 1) {
    using U = std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>;
    U bits;
    std::memcpy(&bits, &v, sizeof(U));
    bits = byte_swap(bits);
    std::memcpy(p, &bits, sizeof(U));
  } else {
    std::memcpy(p, &v, sizeof(T));
  }
  p += sizeof(T);
}

void append_number(std::string& s, float v) {
  char buf[32];
  // Shortest text that reads back to the same float.
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

void append_number(std::string& s, int32_t v) {
  char buf[16];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

// A value preceded by its separator.
template <typename T>
void append_field(std::string& s, T v) {
  s.push_back(' ');
  append_number(s, v);
}

void append_vec3(std::string& s, const Vec3f& v) {
  append_number(s, v.x());
  append_field(s, v.y());
  append_field(s, v.z());
}

const char* format_line(PlyFormat format) {
  return format == PlyFormat::kAscii ? "format ascii 1.0\n" : "format binary_little_endian 1.0\n";
}

template <typename T>
bool per_point(const std::vector<T>& attribute, size_t n) {
  return !attribute.empty() && attribute.size() == n;
}

StatusOr<std::string> read_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    const std::string message = path + ": cannot open: " + errno_text(error);
    return error == ENOENT ? not_found(message) : io_error(message);
  }
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    const int error = errno;
    ::close(fd);
    return io_error(path + ": cannot stat: " + errno_text(error));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd);
    return io_error(path + ": is a directory");
  }
  std::string bytes;
  // st_size is a hint (0 for pipes); the loop reads until end of file either way.
  size_t capacity = S_ISREG(st.st_mode) && st.st_size > 0 ? static_cast<size_t>(st.st_size) : 65536;
  bytes.resize(capacity);
  size_t used = 0;
  while (true) {
    if (used == bytes.size()) bytes.resize(bytes.size() * 2);
    const ssize_t got = ::read(fd, bytes.data() + used, bytes.size() - used);
    if (got < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      return io_error(path + ": cannot read: " + errno_text(error));
    }
    if (got == 0) break;
    used += static_cast<size_t>(got);
  }
  ::close(fd);
  bytes.resize(used);
  return bytes;
}

}  // namespace

// ---------------------------------------------------------------------------
// Public API

StatusOr<PlyData> parse_ply(std::string_view bytes, const std::string& name) {
  auto header = parse_header(bytes);
  if (!header.ok()) return header.status().with_context(name);
  PlyData data;
  Status status;
  if (header->encoding == Encoding::kAscii) {
    AsciiCursor cursor(bytes, header->data_offset, header->data_line);
    status = read_body(cursor, *header, &data);
  } else {
    const bool file_little = header->encoding == Encoding::kBinaryLittleEndian;
    BinaryCursor cursor(bytes, header->data_offset, file_little != kNativeLittleEndian);
    status = read_body(cursor, *header, &data);
  }
  if (!status.ok()) return status.with_context(name);
  assert(data.cloud.is_consistent());
  return data;
}

StatusOr<PlyData> read_ply(const std::string& path) {
  ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return parse_ply(bytes, path);
}

StatusOr<TriangleMesh> read_ply_mesh(const std::string& path) {
  ASSIGN_OR_RETURN(PlyData data, read_ply(path));
  if (data.triangles.empty()) {
    return invalid_argument(path + ": has no faces; a mesh is needed (is it a point cloud?)");
  }
  TriangleMesh mesh;
  mesh.vertices = std::move(data.cloud.positions);
  mesh.normals = std::move(data.cloud.normals);
  mesh.confidence = std::move(data.cloud.confidence);
  mesh.triangles = std::move(data.triangles);
  return mesh;
}

std::string encode_ply(const PointCloud& cloud, PlyFormat format) {
  // Attributes whose length does not match the positions are a caller bug
  // (is_consistent); leaving them out keeps the file self-consistent regardless.
  assert(cloud.is_consistent());
  const size_t n = cloud.size();
  const bool normals = per_point(cloud.normals, n);
  const bool intensity = per_point(cloud.intensity, n);
  const bool confidence = per_point(cloud.confidence, n);
  const bool camera = per_point(cloud.camera, n);
  const bool laser = per_point(cloud.laser, n);
  const bool frame = per_point(cloud.frame, n);
  const size_t num_centres = cloud.camera_centres.size();

  std::string s = "ply\n";
  s += format_line(format);
  s += "comment bodyscan point cloud, mm, Y up\n";
  s += "element vertex " + std::to_string(n) + "\n";
  s += "property float x\nproperty float y\nproperty float z\n";
  if (normals) s += "property float nx\nproperty float ny\nproperty float nz\n";
  if (intensity) s += "property float intensity\n";
  if (confidence) s += "property float confidence\n";
  if (camera) s += "property int camera\n";
  if (laser) s += "property int laser\n";
  if (frame) s += "property int frame\n";
  if (num_centres > 0) {
    s += "element camera " + std::to_string(num_centres) + "\n";
    s += "property float x\nproperty float y\nproperty float z\n";
  }
  s += "end_header\n";

  if (format == PlyFormat::kBinaryLittleEndian) {
    const size_t record = 12 + (normals ? 12 : 0) + 4 * (intensity + confidence + camera + laser + frame);
    const size_t header_size = s.size();
    s.resize(header_size + n * record + num_centres * 12);
    char* p = s.data() + header_size;
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) put(p, cloud.positions[i][k]);
      if (normals) {
        for (int k = 0; k < 3; ++k) put(p, cloud.normals[i][k]);
      }
      if (intensity) put(p, cloud.intensity[i]);
      if (confidence) put(p, cloud.confidence[i]);
      if (camera) put(p, cloud.camera[i]);
      if (laser) put(p, cloud.laser[i]);
      if (frame) put(p, cloud.frame[i]);
    }
    for (const Vec3f& c : cloud.camera_centres) {
      for (int k = 0; k < 3; ++k) put(p, c[k]);
    }
    assert(p == s.data() + s.size());
    return s;
  }

  s.reserve(s.size() + n * 40);
  for (size_t i = 0; i < n; ++i) {
    append_vec3(s, cloud.positions[i]);
    if (normals) {
      s.push_back(' ');
      append_vec3(s, cloud.normals[i]);
    }
    if (intensity) append_field(s, cloud.intensity[i]);
    if (confidence) append_field(s, cloud.confidence[i]);
    if (camera) append_field(s, cloud.camera[i]);
    if (laser) append_field(s, cloud.laser[i]);
    if (frame) append_field(s, cloud.frame[i]);
    s.push_back('\n');
  }
  for (const Vec3f& c : cloud.camera_centres) {
    append_vec3(s, c);
    s.push_back('\n');
  }
  return s;
}

std::string encode_ply(const TriangleMesh& mesh, PlyFormat format) {
  assert(mesh.is_consistent());
  // Indices are written as int, the type every PLY reader understands.
  assert(mesh.vertices.size() <= static_cast<size_t>(std::numeric_limits<int32_t>::max()));
  const size_t n = mesh.vertices.size();
  const bool normals = per_point(mesh.normals, n);
  const bool confidence = per_point(mesh.confidence, n);

  std::string s = "ply\n";
  s += format_line(format);
  s += "comment bodyscan mesh, mm, Y up, counter-clockwise seen from outside\n";
  s += "element vertex " + std::to_string(n) + "\n";
  s += "property float x\nproperty float y\nproperty float z\n";
  if (normals) s += "property float nx\nproperty float ny\nproperty float nz\n";
  if (confidence) s += "property float confidence\n";
  s += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  s += "property list uchar int vertex_indices\n";
  s += "end_header\n";

  if (format == PlyFormat::kBinaryLittleEndian) {
    const size_t header_size = s.size();
    s.resize(header_size + n * ((normals ? 24 : 12) + (confidence ? 4 : 0)) + mesh.triangles.size() * 13);
    char* p = s.data() + header_size;
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) put(p, mesh.vertices[i][k]);
      if (normals) {
        for (int k = 0; k < 3; ++k) put(p, mesh.normals[i][k]);
      }
      if (confidence) put(p, mesh.confidence[i]);
    }
    for (const Triangle& t : mesh.triangles) {
      put(p, uint8_t{3});
      for (int k = 0; k < 3; ++k) put(p, static_cast<int32_t>(t[k]));
    }
    assert(p == s.data() + s.size());
    return s;
  }

  s.reserve(s.size() + n * (normals ? 60 : 30) + mesh.triangles.size() * 24);
  for (size_t i = 0; i < n; ++i) {
    append_vec3(s, mesh.vertices[i]);
    if (normals) {
      s.push_back(' ');
      append_vec3(s, mesh.normals[i]);
    }
    if (confidence) append_field(s, mesh.confidence[i]);
    s.push_back('\n');
  }
  for (const Triangle& t : mesh.triangles) {
    s.push_back('3');
    for (uint32_t index : t) append_field(s, static_cast<int32_t>(index));
    s.push_back('\n');
  }
  return s;
}

Status write_ply(const std::string& path, const PointCloud& cloud, PlyFormat format) {
  if (!cloud.is_consistent()) {
    return invalid_argument(path +
                            ": not written: the point cloud's attributes do not have one "
                            "entry per point, or a camera id has no camera centre");
  }
  return write_file_atomically(path, encode_ply(cloud, format));
}

Status write_ply(const std::string& path, const TriangleMesh& mesh, PlyFormat format) {
  if (!mesh.is_consistent()) {
    return invalid_argument(path +
                            ": not written: a triangle index is out of range, or the "
                            "normals or confidences are not one per vertex");
  }
  if (mesh.vertices.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    return out_of_range(path + ": not written: more vertices than a PLY int index can address");
  }
  return write_file_atomically(path, encode_ply(mesh, format));
}

}  // namespace bodyscan
