// open_source: each accepted form of a source name opens the matching
// source; anything else is an error naming it.
#include "ofv/sources/open_source.h"

#include "ofv/sources/openni2_source.h"
#include "ofv/sources/pcd_sequence.h"
#include "ofv/sources/tum_sequence.h"

#include "scratch.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;

namespace ofv {
namespace {

/// A fresh path under the test's scratch folder.
fs::path scratch(const std::string& name) {
  const fs::path path = fs::path(test::scratch_dir()) / ("ofv_open_source_" + name);
  fs::remove_all(path);
  return path;
}

RgbdFrame frame() {
  const Eigen::Vector3d target(0.0, 0.0, 0.0675);
  return test::table_and_case().render(
      test::vga(160), test::look_at(target + Eigen::Vector3d(0.0, -0.45, 0.22), target), nullptr,
      0.0);
}

/// The message of what f throws as E, or "no exception".
template <typename E, typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "no exception";
}

TEST(OpenSource, TumFolderOpensATumSequence) {
  const fs::path dir = scratch("tum");
  TumSequenceWriter(dir.string()).write(frame());
  const auto source = open_source(dir.string(), -1.0f);
  ASSERT_NE(dynamic_cast<TumSequenceSource*>(source.get()), nullptr);
  EXPECT_TRUE(source->next());
}

TEST(OpenSource, PcdFolderOpensAPcdSequence) {
  const fs::path dir = scratch("pcd");
  PcdSequenceWriter(dir.string()).write(frame());
  const auto source = open_source(dir.string(), -1.0f);
  ASSERT_NE(dynamic_cast<PcdSequenceSource*>(source.get()), nullptr);
  EXPECT_TRUE(source->next());
}

TEST(OpenSource, OniFileOpensARecording) {
  const fs::path path = scratch("case.oni");
  {
    OniWriter writer(path.string());
    writer.write(frame());
    writer.close();
  }
  const auto source = open_source(path.string(), -1.0f);
  const auto* oni = dynamic_cast<OpenNi2Source*>(source.get());
  ASSERT_NE(oni, nullptr);
  EXPECT_TRUE(oni->is_file());
  EXPECT_TRUE(source->next());
}

TEST(OpenSource, OpenNi2UriOpensTheDeviceItNames) {
  // No such device: OpenNI2's own error, naming the URI after the scheme.
  EXPECT_NE(error_of<std::runtime_error>([] {
              open_source("openni2://no-such-device", 1.0f);
            }).find("no-such-device"),
            std::string::npos);
}

TEST(OpenSource, OtherNamesAreErrorsNamingTheSource) {
  const std::string missing_oni = scratch("missing.oni").string();
  EXPECT_NE(error_of<std::invalid_argument>([&] {
              open_source(missing_oni, -1.0f);
            }).find(missing_oni + ": no such .oni file"),
            std::string::npos);
  const fs::path empty = scratch("empty");
  fs::create_directories(empty);
  EXPECT_NE(error_of<std::invalid_argument>([&] {
              open_source(empty.string(), -1.0f);
            }).find(empty.string() + ": not a TUM RGB-D directory"),
            std::string::npos);
  const std::string nothing = scratch("nothing").string();
  EXPECT_NE(error_of<std::invalid_argument>([&] { open_source(nothing, -1.0f); }).find(nothing),
            std::string::npos);
}

}  // namespace
}  // namespace ofv
