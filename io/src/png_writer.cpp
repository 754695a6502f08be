#include "frep/io/png_writer.h"

#include <png.h>

#include <cstring>

#include "frep/io/error.h"

namespace frep::io {

void writePng(const std::string& path, const RgbImage& image) {
  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  info.width = static_cast<png_uint_32>(image.width);
  info.height = static_cast<png_uint_32>(image.height);
  info.format = PNG_FORMAT_RGB;
  int ok = png_image_write_to_file(&info, path.c_str(), 0, image.rgb.data(), 0, nullptr);
  std::string reason = info.message;
  png_image_free(&info);
  if (!ok) throw ioError("cannot write PNG '" + path + "': " + reason);
}

}  // namespace frep::io
