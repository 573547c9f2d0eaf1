// Bytes to values for the VTK readers: base64, zlib blocks, typed words and ascii tokens.

#include <zlib.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "network_detail.hpp"
#include "surface_io_detail.hpp"

namespace msfem::cases::detail {

namespace {

int base64_digit(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

}  // namespace

std::string number_text(double value) {
  std::string text;
  append_number(text, value);
  return text;
}

std::size_t max_values_for(std::size_t file_size) {
  return 1032 * (file_size + 64);
}

// ---- types ----

std::size_t size_of(ValueType type) {
  switch (type) {
    case ValueType::int8:
    case ValueType::uint8:
    case ValueType::string:
      return 1;
    case ValueType::int16:
    case ValueType::uint16:
      return 2;
    case ValueType::int32:
    case ValueType::uint32:
    case ValueType::float32:
      return 4;
    case ValueType::int64:
    case ValueType::uint64:
    case ValueType::float64:
      return 8;
  }
  return 1;
}

bool is_integer(ValueType type) {
  return type != ValueType::float32 && type != ValueType::float64 && type != ValueType::string;
}

bool is_real(ValueType type) {
  return type == ValueType::float32 || type == ValueType::float64;
}

namespace {
const std::pair<const char*, ValueType> xml_types[] = {
    {"Int8", ValueType::int8},       {"UInt8", ValueType::uint8},   {"Int16", ValueType::int16},
    {"UInt16", ValueType::uint16},   {"Int32", ValueType::int32},   {"UInt32", ValueType::uint32},
    {"Int64", ValueType::int64},     {"UInt64", ValueType::uint64}, {"Float32", ValueType::float32},
    {"Float64", ValueType::float64}, {"String", ValueType::string}};
}  // namespace

const char* xml_type_name(ValueType type) {
  for (const auto& [name, known] : xml_types)
    if (known == type) return name;
  return "?";
}

bool parse_xml_type(std::string_view name, ValueType& type) {
  for (const auto& [known_name, known] : xml_types)
    if (name == known_name) {
      type = known;
      return true;
    }
  return false;
}

std::size_t VtkArray::size() const {
  if (type == ValueType::string) return strings.size();
  return is_integer(type) ? integers.size() : reals.size();
}

// ---- values ----

namespace {

bool in_range(long long value, ValueType type) {
  switch (type) {
    case ValueType::int8:
      return value >= -128 && value <= 127;
    case ValueType::uint8:
      return value >= 0 && value <= 255;
    case ValueType::int16:
      return value >= -32768 && value <= 32767;
    case ValueType::uint16:
      return value >= 0 && value <= 65535;
    case ValueType::int32:
      return value >= std::numeric_limits<std::int32_t>::min() &&
             value <= std::numeric_limits<std::int32_t>::max();
    case ValueType::uint32:
      return value >= 0 && value <= 0xffffffffLL;
    case ValueType::uint64:
      return value >= 0;
    default:
      return true;
  }
}

}  // namespace

bool decode_words(std::string_view bytes, std::size_t count, ValueType type, bool big_endian,
                  VtkArray& array) {
  const std::size_t size = size_of(type);
  if (is_integer(type))
    array.integers.reserve(array.integers.size() + count);
  else
    array.reals.reserve(array.reals.size() + count);
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t raw = 0;
    for (std::size_t k = 0; k < size; ++k) {
      const std::size_t byte = big_endian ? k : size - 1 - k;
      raw = (raw << 8) | static_cast<unsigned char>(bytes[i * size + byte]);
    }
    switch (type) {
      case ValueType::int8:
        array.integers.push_back(static_cast<std::int8_t>(raw));
        break;
      case ValueType::uint8:
      case ValueType::string:
        array.integers.push_back(static_cast<std::uint8_t>(raw));
        break;
      case ValueType::int16:
        array.integers.push_back(static_cast<std::int16_t>(raw));
        break;
      case ValueType::uint16:
        array.integers.push_back(static_cast<std::uint16_t>(raw));
        break;
      case ValueType::int32:
        array.integers.push_back(static_cast<std::int32_t>(raw));
        break;
      case ValueType::uint32:
        array.integers.push_back(static_cast<std::uint32_t>(raw));
        break;
      case ValueType::int64:
        array.integers.push_back(static_cast<std::int64_t>(raw));
        break;
      case ValueType::uint64:
        if (raw > static_cast<std::uint64_t>(std::numeric_limits<long long>::max())) return false;
        array.integers.push_back(static_cast<long long>(raw));
        break;
      case ValueType::float32: {
        const auto bits = static_cast<std::uint32_t>(raw);
        float value;
        std::memcpy(&value, &bits, sizeof value);
        array.reals.push_back(value);
        break;
      }
      case ValueType::float64: {
        double value;
        std::memcpy(&value, &raw, sizeof value);
        array.reals.push_back(value);
        break;
      }
    }
  }
  return true;
}

bool parse_value(std::string_view token, ValueType type, VtkArray& array) {
  if (is_integer(type)) {
    long long value;
    if (!parse_integer(token, value) || !in_range(value, type)) return false;
    array.integers.push_back(value);
    return true;
  }
  double value;
  if (!parse_double(token, value)) return false;
  // VTK reads a Float32 array's text into floats: the same values a binary Float32 array gives.
  array.reals.push_back(type == ValueType::float32 ? static_cast<double>(static_cast<float>(value))
                                                   : value);
  return true;
}

// ---- base64 ----

bool Base64Reader::next_group() {
  int digits[4];
  int got = 0;
  int padding = 0;
  while (got < 4) {
    while (pos_ < text_.size() && is_blank(text_[pos_]))
      ++pos_;
    if (pos_ == text_.size()) return false;
    const char c = text_[pos_++];
    if (c == '=') {
      // Padding only completes a group: "xx==" or "xxx=".
      if (got < 2) return false;
      ++padding;
      digits[got++] = 0;
      continue;
    }
    if (padding > 0) return false;
    const int digit = base64_digit(c);
    if (digit < 0) return false;
    digits[got++] = digit;
  }
  const std::uint32_t bits = (static_cast<std::uint32_t>(digits[0]) << 18) |
                             (static_cast<std::uint32_t>(digits[1]) << 12) |
                             (static_cast<std::uint32_t>(digits[2]) << 6) |
                             static_cast<std::uint32_t>(digits[3]);
  group_[0] = static_cast<unsigned char>(bits >> 16);
  group_[1] = static_cast<unsigned char>(bits >> 8);
  group_[2] = static_cast<unsigned char>(bits);
  have_ = static_cast<std::size_t>(3 - padding);
  used_ = 0;
  return true;
}

bool Base64Reader::read(std::size_t n, std::string& out) {
  if (n > bound()) return false;
  out.reserve(out.size() + n);
  while (n > 0) {
    if (used_ == have_ && !next_group()) return false;
    const std::size_t take = std::min(n, have_ - used_);
    out.append(reinterpret_cast<const char*>(group_ + used_), take);
    used_ += take;
    n -= take;
  }
  return true;
}

// ---- zlib ----

std::string inflate_exact(std::string_view compressed, std::size_t size, std::string& out) {
  // No deflate stream expands more than 1032:1; a header that says otherwise is corrupt, and
  // believing it would allocate whatever it asks for.
  if (size / 1032 > compressed.size() + 64)
    return "it claims " + std::to_string(size) + " bytes from " +
           std::to_string(compressed.size()) + " compressed bytes";
  if (size > std::numeric_limits<uInt>::max() ||
      compressed.size() > std::numeric_limits<uInt>::max())
    return "a block larger than 4 GiB";
  const std::size_t start = out.size();
  out.resize(start + size);
  z_stream stream{};
  if (inflateInit(&stream) != Z_OK) return "zlib cannot start";
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  stream.avail_in = static_cast<uInt>(compressed.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data() + start);
  stream.avail_out = static_cast<uInt>(size);
  const int result = inflate(&stream, Z_FINISH);
  const std::string message = stream.msg ? stream.msg : "";
  const std::size_t produced = size - stream.avail_out;
  inflateEnd(&stream);
  if (result == Z_STREAM_END && produced == size) return "";
  out.resize(start);
  if (result == Z_STREAM_END)
    return "it inflates to " + std::to_string(produced) + " bytes, not " + std::to_string(size);
  if (result == Z_BUF_ERROR && stream.avail_out == 0)
    return "it inflates to more than " + std::to_string(size) + " bytes";
  if (result == Z_BUF_ERROR) return "the compressed data ends early";
  return message.empty() ? "inflate error " + std::to_string(result) : message;
}

}  // namespace msfem::cases::detail
