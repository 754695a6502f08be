// 8-bit RGB PNG output through libpng.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace frep::io {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // row-major from the top row, 3 bytes per pixel
  RgbImage(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0) {}
  uint8_t* pixel(int col, int row) { return &rgb[(size_t(row) * size_t(width) + size_t(col)) * 3]; }
};

// Writes image to path (overwriting); throws Error(kExitIoError) with libpng's reason.
void writePng(const std::string& path, const RgbImage& image);

}  // namespace frep::io
