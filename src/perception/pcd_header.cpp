// The PCD header check, kept apart from PCL (pcd_sequence.cpp) so that it can
// be fuzzed on its own.
#include "ofv/sources/pcd_sequence.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace ofv {

void check_pcd_header(std::istream& in, std::uint64_t file_size, const std::string& path) {
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument(path + ": invalid PCD header: " + what);
  };
  std::map<std::string, std::vector<std::string>> header;
  std::string line;
  while (header.count("DATA") == 0 && std::getline(in, line) && in.tellg() < 65536) {
    std::istringstream words(line);
    std::string key, word;
    if (!(words >> key) || key[0] == '#') {
      continue;
    }
    if (header.count(key) != 0) {
      fail("duplicate " + key);
    }
    auto& values = header[key];
    while (words >> word) {
      values.push_back(word);
    }
  }
  for (const char* key : {"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "POINTS", "DATA"}) {
    if (header.count(key) == 0) {
      fail(std::string("no ") + key + " line");
    }
  }
  const auto& fields = header["FIELDS"];
  for (const char* key : {"SIZE", "TYPE", "COUNT"}) {
    if (fields.empty() || header[key].size() != fields.size()) {
      fail(std::string(key) + " has " + std::to_string(header[key].size()) + " values for " +
           std::to_string(fields.size()) + " FIELDS");
    }
  }
  const auto count = [&](const char* key, const std::string& text) {
    std::size_t used = 0;
    unsigned long long v = 0;
    try {
      v = std::stoull(text, &used);
    } catch (const std::exception&) {
    }
    if (used == 0 || used != text.size() || text[0] == '-') {
      fail(std::string(key) + " " + text.substr(0, 20) + ": expected a count");
    }
    return v;
  };
  std::uint64_t point_bytes = 0;
  std::map<std::string, std::string> kinds;  // field -> TYPE SIZE COUNT, e.g. "F41"
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string& size = header["SIZE"][i];
    const std::string& type = header["TYPE"][i];
    if (size != "1" && size != "2" && size != "4" && size != "8") {
      fail("SIZE of " + fields[i] + " " + size.substr(0, 20) + ": expected 1, 2, 4 or 8");
    }
    if (type != "F" && type != "I" && type != "U") {
      fail("TYPE of " + fields[i] + " " + type.substr(0, 20) + ": expected F, I or U");
    }
    const std::uint64_t n = count("COUNT", header["COUNT"][i]);
    if (n == 0 || n > 1024) {
      fail("COUNT of " + fields[i] + " " + std::to_string(n) + ": expected 1 to 1024");
    }
    point_bytes += std::stoull(size) * n;
    kinds[fields[i]] = type + size + (n == 1 ? "1" : "n");
  }
  const auto kind = [&](const char* f) { return kinds.count(f) != 0 ? kinds[f] : std::string("---"); };
  for (const char* f : {"x", "y", "z"}) {
    if (kind(f) != "F41") {
      fail(std::string("field ") + f + ": expected a 4-byte float (FIELDS x y z rgb|rgba)");
    }
  }
  if (kind("rgb").substr(1) != "41" && kind("rgba").substr(1) != "41") {
    fail("no 4-byte rgb or rgba field");
  }
  if (header["WIDTH"].size() != 1 || header["HEIGHT"].size() != 1 || header["POINTS"].size() != 1) {
    fail("WIDTH, HEIGHT and POINTS take one value each");
  }
  const std::uint64_t width = count("WIDTH", header["WIDTH"][0]);
  const std::uint64_t height = count("HEIGHT", header["HEIGHT"][0]);
  const std::uint64_t points = count("POINTS", header["POINTS"][0]);
  if (width == 0 || height == 0 || width > kMaxPcdPoints || height > kMaxPcdPoints ||
      points != width * height) {
    fail("POINTS " + std::to_string(points) + " for WIDTH " + std::to_string(width) +
         " x HEIGHT " + std::to_string(height));
  }
  if (points > kMaxPcdPoints) {
    fail("POINTS " + std::to_string(points) + ": more than " + std::to_string(kMaxPcdPoints));
  }
  const std::string data = header["DATA"].empty() ? "" : header["DATA"][0];
  const std::uint64_t start = in ? static_cast<std::uint64_t>(in.tellg()) : file_size;
  if (data == "binary") {
    if (start + points * point_bytes > file_size) {
      fail("DATA binary: " + std::to_string(points) + " points of " + std::to_string(point_bytes) +
           " bytes need " + std::to_string(points * point_bytes) + " bytes, the file has " +
           std::to_string(file_size - start) + " after the header");
    }
  } else if (data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed
    in.read(reinterpret_cast<char*>(sizes), sizeof sizes);
    if (!in || start + 8 + sizes[0] > file_size || sizes[1] != points * point_bytes) {
      fail("DATA binary_compressed: the sizes " + std::to_string(sizes[0]) + " and " +
           std::to_string(sizes[1]) + " do not fit the points and the file");
    }
  } else if (data != "ascii") {
    fail("DATA " + data.substr(0, 20) + ": expected ascii, binary or binary_compressed");
  }
}

void check_pcd_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (!in || ec) {
    throw std::invalid_argument(path + ": cannot open the PCD file");
  }
  check_pcd_header(in, file_size, path);
}

}  // namespace ofv
