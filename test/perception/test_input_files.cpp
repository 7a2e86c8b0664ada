// End to end: recorded input files that are broken, hostile or lying about
// their content make `ofv perceive` exit 2 with one line naming the file,
// never crash it (issue #13, item 1).
#include "ofv/sources/openni2_source.h"
#include "ofv/sources/pcd_sequence.h"
#include "ofv/sources/tum_sequence.h"

#include "cli_run.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace ofv {
namespace {

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

std::vector<RgbdFrame> two_frames() {
  std::vector<RgbdFrame> frames;
  for (int k = 0; k < 2; ++k) {
    frames.push_back(test::table_and_case().render(test::vga(160), test::front_camera(), nullptr,
                                                   k / 30.0));
  }
  return frames;
}

/// Expects exit 2, one line on stderr naming every word of `mentions`, no crash.
void expect_bad_input(const std::string& args, const std::vector<std::string>& mentions,
                      const std::string& label) {
  const CommandRun r = run(args);
  EXPECT_EQ(r.code, 2) << label << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << label << ": " << r.err;
  for (const std::string& m : mentions) {
    EXPECT_NE(r.err.find(m), std::string::npos) << label << ": " << r.err;
  }
}

TEST(InputFiles, BrokenPcdFramesAreExitTwoNamingTheFile) {
  const fs::path dir = fs::path(test::scratch_dir()) / "ofv_bad_pcd";
  fs::remove_all(dir);
  {
    PcdSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : two_frames()) {
      writer.write(f);
    }
  }
  const fs::path frame = dir / "000001.pcd";
  const std::string good = file_text(frame);
  ASSERT_EQ(run("perceive " + dir.string()).code, 0);
  const std::size_t data = good.find("DATA binary\n") + 12;
  const std::string header = good.substr(0, data);
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string h = header;
    h.replace(h.find(from), from.size(), to);
    return h + good.substr(data);
  };
  const std::string ascii_head =
      "VERSION .7\nFIELDS x y z rgba\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\n"
      "HEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"empty", ""},
      {"garbage", std::string("\x89\x00\xff garbage\n\x01\x02", 14)},
      {"truncated", good.substr(0, data + (good.size() - data) / 2)},
      {"header only", header},
      {"points not width x height", replaced("POINTS 19200", "POINTS 19199")},
      {"a billion points", replaced("WIDTH 160", "WIDTH 6250000")},
      {"no colour", replaced("FIELDS x y z rgba", "FIELDS x y z w")},
      {"x not a float", replaced("TYPE F F F U", "TYPE U F F U")},
      {"sizes missing", replaced("SIZE 4 4 4 4", "SIZE 4 4 4")},
      {"compressed lies", replaced("DATA binary", "DATA binary_compressed")},
      {"ascii garbage", ascii_head + "nan nan x\n1 2\n"},
      {"ascii short", ascii_head + "1 2 3 4\n"},
  };
  for (const auto& [label, bytes] : cases) {
    spit(frame, bytes);
    expect_bad_input("perceive " + dir.string(), {"000001.pcd"}, label);
  }
}

/// A PNG with its IHDR size set to `width` x `height` (CRC updated), pixels unchanged.
std::string with_png_size(std::string png, std::uint32_t width, std::uint32_t height) {
  for (int k = 0; k < 4; ++k) {
    png[16 + k] = static_cast<char>(width >> (24 - 8 * k));
    png[20 + k] = static_cast<char>(height >> (24 - 8 * k));
  }
  std::uint32_t crc = 0xFFFFFFFFu;  // CRC-32 of the chunk type and data (bytes 12 to 28)
  for (int i = 12; i < 29; ++i) {
    crc ^= static_cast<std::uint8_t>(png[i]);
    for (int b = 0; b < 8; ++b) {
      crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
  }
  crc = ~crc;
  for (int k = 0; k < 4; ++k) {
    png[29 + k] = static_cast<char>(crc >> (24 - 8 * k));
  }
  return png;
}

TEST(InputFiles, BrokenTumImagesAndPosesAreExitTwoNamingTheFile) {
  const fs::path dir = fs::path(test::scratch_dir()) / "ofv_bad_tum";
  fs::remove_all(dir);
  {
    TumSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : two_frames()) {
      writer.write(f);
    }
  }
  ASSERT_EQ(run("perceive " + dir.string()).code, 0);
  const fs::path depth = dir / "depth" / "0.033333.png";
  const fs::path rgb = dir / "rgb" / "0.033333.png";
  const std::string good_depth = file_text(depth), good_rgb = file_text(rgb);
  std::string corrupt = good_depth;
  for (std::size_t i = 60; i + 20 < corrupt.size(); i += 7) {
    corrupt[i] = static_cast<char>(corrupt[i] ^ 0x55);
  }
  const fs::path rgb16 = dir / "rgb16.png";
  ASSERT_TRUE(cv::imwrite(rgb16.string(), cv::Mat(120, 160, CV_16UC3, cv::Scalar(1000, 2000, 3000))));
  struct Case {
    std::string label;
    fs::path file;
    std::string bytes;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases{
      {"corrupt depth", depth, corrupt, {depth.string(), "corrupt"}},
      {"text depth", depth, "not a png\n", {depth.string()}},
      {"empty depth", depth, "", {depth.string()}},
      {"16-bit RGB depth", depth, file_text(rgb16), {depth.string(), "16-bit RGB"}},
      {"8-bit RGB depth", depth, good_rgb, {depth.string(), "8-bit RGB"}},
      {"30000 x 30000 depth", depth, with_png_size(good_depth, 30000, 30000), {depth.string(), "30000x30000"}},
      {"corrupt colour", rgb, corrupt, {rgb.string()}},
      {"30000 x 30000 colour", rgb, with_png_size(good_rgb, 30000, 30000), {rgb.string(), "30000x30000"}},
  };
  for (const Case& c : cases) {
    spit(c.file, c.bytes);
    expect_bad_input("perceive " + dir.string(), c.mentions, c.label);
    spit(depth, good_depth);
    spit(rgb, good_rgb);
  }
  // A depth image without a ground-truth pose near its time.
  const std::string poses = file_text(dir / "groundtruth.txt");
  spit(dir / "groundtruth.txt", poses.substr(0, poses.rfind('\n', poses.size() - 2) + 1));
  expect_bad_input("perceive " + dir.string(), {"groundtruth.txt", "0.033333"}, "missing pose");
  fs::remove(dir / "groundtruth.txt");
  expect_bad_input("perceive " + dir.string(), {"groundtruth.txt", "missing"}, "no ground truth");
}

TEST(InputFiles, OniWithAnyHeaderByteChangedIsRefusedOrPlays) {
  const fs::path good_path = fs::path(test::scratch_dir()) / "ofv_good.oni";
  {
    OniWriter writer(good_path.string());
    for (const RgbdFrame& f : two_frames()) {
      writer.write(f);
    }
  }
  const std::string good = file_text(good_path);
  ASSERT_NO_THROW(check_oni_file(good_path.string()));
  // Every byte but the frames' pixels is flipped (XOR 0xFF); the file header's
  // and the record headers' bytes are also incremented (sizes and ids off by one).
  std::vector<int> kind(good.size(), 1);  // 0: pixels, 1: fields, 2: header
  std::fill_n(kind.begin(), 24, 2);
  for (std::size_t at = 24; at + 28 <= good.size();) {
    std::uint32_t type = 0, fields = 0, payload = 0;
    std::memcpy(&type, good.data() + at + 4, 4);
    std::memcpy(&fields, good.data() + at + 12, 4);
    std::memcpy(&payload, good.data() + at + 16, 4);
    std::fill_n(kind.begin() + static_cast<std::ptrdiff_t>(at), 28, 2);
    std::fill_n(kind.begin() + static_cast<std::ptrdiff_t>(at + fields), payload, 0);
    at += fields + payload;
    if (type == 0x0B) {
      break;
    }
  }
  const fs::path path = fs::path(test::scratch_dir()) / "ofv_mutated.oni";
  OpenNi2Options options;
  options.timeout_ms = 300;
  int refused = 0, played = 0;
  std::vector<std::size_t> refused_offsets;
  for (std::size_t k = 0; k < good.size(); ++k) {
    for (int change = 0; change < kind[k]; ++change) {
      std::string bytes = good;
      bytes[k] = static_cast<char>(change == 0 ? bytes[k] ^ 0xFF : bytes[k] + 1);
      spit(path, bytes);
      try {
        check_oni_file(path.string());
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(path.string() + ": offset "), std::string::npos) << e.what();
        ++refused;
        refused_offsets.push_back(k);
        continue;
      }
      // Accepted: it plays, or the source reports an error; it must not crash.
      // (OpenNI2's player, which played recordings before ofv did, crashed
      // twice in CI here: the line names the mutation.)
      std::cerr << "playing the mutation of byte " << k << (change == 0 ? " (flipped)" : " (+1)") << '\n';
      try {
        OpenNi2Source source(path.string(), options);
        while (source.next()) {
        }
      } catch (const std::exception&) {
      }
      ++played;
    }
  }
  EXPECT_GT(refused, 0);
  // Fewer poses than frames: no frame silently takes the last pose.
  const std::string poses = file_text(good_path.string() + ".poses.txt");
  spit(good_path.string() + ".poses.txt", poses.substr(0, poses.rfind('\n', poses.size() - 2) + 1));
  expect_bad_input("perceive " + good_path.string(), {good_path.string() + ".poses.txt", "1 poses for 2 frames"},
                   "missing pose");
  std::cerr << refused << " mutations refused, " << played << " played\n";
  // Through the command line: exit 2, one line naming the file and the offset.
  for (const std::size_t k : {std::size_t{0}, std::size_t{20}, std::size_t{24 + 12}, refused_offsets.back()}) {
    std::string bytes = good;
    bytes[k] = static_cast<char>(bytes[k] ^ 0xFF);
    spit(path, bytes);
    expect_bad_input("perceive " + path.string(), {path.string(), "offset"}, "byte " + std::to_string(k));
  }
}

}  // namespace
}  // namespace ofv
