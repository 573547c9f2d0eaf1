#pragma once
// An 8-bit, non-interlaced RGB or RGBA PNG (what cairo and Chromium write) decoded for the tests
// that check a picture's pixels: its chunks, IDAT inflated with zlib, each row's filter undone
// (PNG specification, section 9).
#include <gtest/gtest.h>
#include <zlib.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace msfem::testing {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< row-major, 3 bytes per pixel
  std::array<int, 3> at(int column, int row) const {
    const std::size_t i = 3 * (std::size_t(row) * std::size_t(width) + std::size_t(column));
    return {{rgb[i], rgb[i + 1], rgb[i + 2]}};
  }
};

inline std::uint32_t big_endian(const std::string& s, std::size_t at) {
  return (std::uint32_t(std::uint8_t(s[at])) << 24) |
         (std::uint32_t(std::uint8_t(s[at + 1])) << 16) |
         (std::uint32_t(std::uint8_t(s[at + 2])) << 8) | std::uint32_t(std::uint8_t(s[at + 3]));
}

inline Image read_png(const std::filesystem::path& file) {
  const std::string bytes = read_text(file);
  Image image;
  if (bytes.size() < 8 || bytes.compare(1, 3, "PNG") != 0) {
    ADD_FAILURE() << file << " is not a PNG";
    return image;
  }
  std::string compressed;
  int channels = 0;
  for (std::size_t at = 8; at + 8 <= bytes.size();) {
    const std::uint32_t length = big_endian(bytes, at);
    const std::string type = bytes.substr(at + 4, 4);
    if (type == "IHDR") {
      image.width = int(big_endian(bytes, at + 8));
      image.height = int(big_endian(bytes, at + 12));
      EXPECT_EQ(bytes[at + 16], 8) << "bit depth";
      channels = bytes[at + 17] == 6 ? 4 : 3;
      EXPECT_EQ(bytes[at + 20], 0) << "interlaced";
    } else if (type == "IDAT") {
      compressed += bytes.substr(at + 8, length);
    }
    at += 12 + length;
  }
  const std::size_t stride = std::size_t(image.width) * std::size_t(channels);
  std::vector<std::uint8_t> raw((stride + 1) * std::size_t(image.height));
  uLongf size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(compressed.data()),
                       compressed.size()),
            Z_OK);
  std::vector<std::uint8_t> pixels(stride * std::size_t(image.height));
  for (int row = 0; row < image.height; ++row) {
    const std::uint8_t filter = raw[std::size_t(row) * (stride + 1)];
    const std::uint8_t* in = &raw[std::size_t(row) * (stride + 1) + 1];
    std::uint8_t* out = &pixels[std::size_t(row) * stride];
    const std::uint8_t* above = row > 0 ? out - stride : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= std::size_t(channels) ? out[i - channels] : 0;
      const int b = above ? above[i] : 0;
      const int c = above && i >= std::size_t(channels) ? above[i - channels] : 0;
      int predictor = 0;
      if (filter == 1) predictor = a;
      if (filter == 2) predictor = b;
      if (filter == 3) predictor = (a + b) / 2;
      if (filter == 4) {
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[i] = std::uint8_t(in[i] + predictor);
    }
  }
  for (std::size_t p = 0; p < std::size_t(image.width) * std::size_t(image.height); ++p)
    for (int k = 0; k < 3; ++k)
      image.rgb.push_back(pixels[p * std::size_t(channels) + std::size_t(k)]);
  return image;
}

}  // namespace msfem::testing
