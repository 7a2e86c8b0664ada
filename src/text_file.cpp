// Reading a whole input file with its size bounded while reading.
#include "ofv/text_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace ofv {

std::string read_text_file(const std::string& path, std::uintmax_t max_bytes, const std::string& what) {
  namespace fs = std::filesystem;
  const auto refuse = [&](const std::string& why) {
    throw std::invalid_argument(path + ": " + why + " (expected a " + what + " file)");
  };
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) refuse("cannot read it (no such file)");
  if (fs::is_directory(status)) refuse("is a directory");
  if (!fs::is_regular_file(status)) refuse("not a regular file (a device, FIFO or socket)");
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(std::string("cannot read it (") + std::strerror(errno) + ")");
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes) refuse("longer than " + std::to_string(max_bytes) + " bytes");
  }
  if (in.bad()) refuse("read error");
  return text;
}

}  // namespace ofv
