// Test helper: a scratch folder of this test process, removed at exit, so
// that test runs side by side (ctest -j, two build trees) never share files.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

namespace ofv::test {

/// The folder, with a trailing slash (like testing::TempDir()).
inline const std::string& scratch_dir() {
  struct Scratch {
    std::filesystem::path path = std::filesystem::path(testing::TempDir()) / ("ofv_test_" + std::to_string(::getpid()));
    Scratch() { std::filesystem::create_directories(path); }
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
