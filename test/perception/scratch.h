// Test helper: a scratch folder of this test process, removed at exit, so
// that test runs side by side (ctest -j, two build trees) never share files.
#pragma once

#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ofv::test {

/// The folder, with a trailing slash (like testing::TempDir()). It is made
/// new by mkdtemp: a folder left by an earlier process of the same pid (one
/// that ended without its destructors) is never reused.
inline const std::string& scratch_dir() {
  struct Scratch {
    std::filesystem::path path;
    Scratch() {
      std::string pattern =
          (std::filesystem::path(testing::TempDir()) / ("ofv_test_" + std::to_string(::getpid()) + "_XXXXXX")).string();
      if (::mkdtemp(pattern.data()) == nullptr)
        throw std::runtime_error("cannot make a scratch folder " + pattern + ": " + std::strerror(errno));
      path = pattern;
    }
    ~Scratch() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Scratch scratch;
  static const std::string dir = scratch.path.string() + "/";
  return dir;
}

}  // namespace ofv::test

namespace ofv {

/// The contents of a file, byte for byte ("" if it cannot be read).
inline std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace ofv
