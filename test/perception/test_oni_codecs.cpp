// The decoders of compressed .oni frames (oni_codecs.h): payloads made by
// encoders written here from the format (or by hand), every way a payload
// can lie refused with a reason, and .oni files with compressed nodes through
// check_oni_file() and ofv's playback, frame by frame as OpenNI2's own player.
#include "../../src/perception/oni_codecs.h"
#include "../../src/perception/oni_format.h"
#include "ofv/sources/openni2_source.h"

#include "openni2_player.h"
#include "scratch.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace ofv {
namespace {

using Bytes = std::vector<std::uint8_t>;
using oni::FrameShape;

/// Nibble-pair encoder shared by 16z and 8z (the writers of oni_codecs.h's
/// formats): differences of at most 6 two to a byte, pairs of zero differences
/// as runs, larger steps escaped by `escape(value, difference)`.
class NibbleWriter {
 public:
  explicit NibbleWriter(Bytes& out) : out_(out) {}
  /// Appends a difference of at most 6 in magnitude; `may_run`: it may join a run of zeros.
  void small(int difference, bool may_run = true) {
    const int nibble = difference + 6;
    if (pending_ < 0) {
      pending_ = nibble;
      pending_may_run_ = may_run;
      return;
    }
    const auto byte = static_cast<std::uint8_t>(pending_ << 4 | nibble);
    if (byte == 0x66 && pending_may_run_) {
      ++zeros_;
    } else {
      flush_zeros();
      out_.push_back(byte);
    }
    pending_ = -1;
  }
  /// Ends the pending nibble (if any) with an escape nibble 0xF, else writes `alone`.
  void escape(std::uint8_t alone) {
    flush_zeros();
    if (pending_ < 0) {
      out_.push_back(alone);
    } else {
      out_.push_back(static_cast<std::uint8_t>(pending_ << 4 | 0x0F));
      pending_ = -1;
    }
  }
  [[nodiscard]] bool pending() const { return pending_ >= 0; }
  /// 8z's whole pixel over two bytes: `first`, then a high nibble that is no difference.
  void whole(std::uint8_t first, int nibble) {
    flush_zeros();
    out_.push_back(first);
    pending_ = nibble;
    pending_may_run_ = false;
  }
  void finish() {
    flush_zeros();
    if (pending_ >= 0) out_.push_back(static_cast<std::uint8_t>(pending_ << 4 | 0x0D));
    pending_ = -1;
  }

 private:
  void flush_zeros() {
    for (; zeros_ > 0; zeros_ -= std::min(zeros_, 15)) out_.push_back(static_cast<std::uint8_t>(0xE0 + std::min(zeros_, 15)));
  }
  Bytes& out_;
  int pending_ = -1;
  bool pending_may_run_ = true;
  int zeros_ = 0;
};

void put16(Bytes& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}

/// 16zP of `values` (each below 0x8000: whole values are 15 bits).
Bytes encode_16z(const std::vector<std::uint16_t>& values) {
  Bytes out;
  put16(out, values.at(0));
  NibbleWriter w(out);
  for (std::size_t k = 1; k < values.size(); ++k) {
    const int difference = values[k - 1] - values[k];
    if (std::abs(difference) <= 6) {
      w.small(difference);
      continue;
    }
    w.escape(0xFF);
    if (std::abs(difference) <= 63) {
      out.push_back(static_cast<std::uint8_t>(difference + 192));
    } else {
      out.push_back(static_cast<std::uint8_t>(values[k] >> 8));
      out.push_back(static_cast<std::uint8_t>(values[k] & 0xFF));
    }
  }
  w.finish();
  return out;
}

/// 16zT: the sorted distinct values as the table, then 16zP of the indices.
Bytes encode_16z_tables(const std::vector<std::uint16_t>& pixels) {
  std::map<std::uint16_t, std::uint16_t> index;
  for (const std::uint16_t p : pixels) index[p] = 0;
  Bytes out;
  put16(out, static_cast<std::uint16_t>(index.size()));
  std::uint16_t next = 0;
  for (auto& [value, i] : index) {
    put16(out, value);
    i = next++;
  }
  std::vector<std::uint16_t> indices;
  for (const std::uint16_t p : pixels) indices.push_back(index[p]);
  const Bytes stream = encode_16z(indices);
  out.insert(out.end(), stream.begin(), stream.end());
  return out;
}

/// Im8z of `bytes`.
Bytes encode_8z(const Bytes& bytes) {
  Bytes out{bytes.at(0)};
  NibbleWriter w(out);
  for (std::size_t k = 1; k < bytes.size(); ++k) {
    const int difference = bytes[k - 1] - bytes[k];
    if (std::abs(difference) <= 6) {
      w.small(difference);
    } else if (w.pending()) {
      w.escape(0);
      out.push_back(bytes[k]);
    } else {
      w.whole(static_cast<std::uint8_t>(0xF0 | bytes[k] >> 4), bytes[k] & 0x0F);
    }
  }
  w.finish();
  return out;
}

std::vector<std::uint16_t> as16(const Bytes& frame) {
  std::vector<std::uint16_t> v(frame.size() / 2);
  std::memcpy(v.data(), frame.data(), v.size() * 2);
  return v;
}

/// decode_frame() that expects success and returns the frame.
Bytes decoded(std::uint32_t codec, const Bytes& payload, const FrameShape& shape) {
  Bytes frame;
  const std::string why = oni::decode_frame(codec, payload.data(), payload.size(), shape, frame);
  EXPECT_EQ(why, "");
  return frame;
}

/// decode_frame()'s reason for refusing `payload`, which must mention `mention`.
void expect_refused(std::uint32_t codec, const Bytes& payload, const FrameShape& shape, const std::string& mention) {
  Bytes frame;
  // A copy of exactly the payload's size: ASan sees a read one byte past it.
  const Bytes exact(payload);
  const std::string why = oni::decode_frame(codec, exact.data(), exact.size(), shape, frame);
  EXPECT_NE(why.find(mention), std::string::npos) << "refusal: '" << why << "', expected to mention '" << mention << "'";
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
}

/// A depth image with what 16z must get right: zeros, long flat runs, small
/// steps, steps of 7 to 63, large jumps (to 0 and back, to 32767).
std::vector<std::uint16_t> test_depth(int width, int height) {
  std::vector<std::uint16_t> d(static_cast<std::size_t>(width * height));
  std::mt19937 random(7);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint16_t v = 0;
      if (x < width / 4) {
        v = 0;  // holes
      } else if (x < width / 2) {
        v = static_cast<std::uint16_t>(800 + 4 * y);  // flat rows: runs
      } else if (x < 3 * width / 4) {
        v = static_cast<std::uint16_t>(1500 + 3 * x + (x % 5 == 0 ? 40 : 0));  // steps, escapes of 7..63
      } else {
        v = static_cast<std::uint16_t>(random() % 4 == 0 ? 0 : 2000 + random() % 30000);  // jumps
      }
      d[static_cast<std::size_t>(y * width + x)] = v;
    }
  }
  d.back() = 32767;
  return d;
}

const FrameShape kDepth64x48{64, 48, 2};

TEST(OniCodecs, HandMade16zDecodesAsWorkedOut) {
  // 1000; 0x67: +0, -1; 0xE1: two repeats; FF C5: -5; FF 12 34: 0x1234;
  // 0x5D: +1, pad; 0x6F 0x81: +0, then escape -(0x81 - 192) = +63.
  const Bytes payload{0xE8, 0x03, 0x67, 0xE1, 0xFF, 0xC5, 0xFF, 0x12, 0x34, 0x5D, 0x6F, 0x81};
  const std::vector<std::uint16_t> expected{1000, 1000, 999, 999, 999, 994, 0x1234, 0x1235, 0x1235, 0x1274};
  EXPECT_EQ(as16(decoded(oni::kCodec16z, payload, {5, 2, 2})), expected);
  EXPECT_EQ(as16(decoded(oni::kCodec16z, encode_16z(expected), {5, 2, 2})), expected);
}

TEST(OniCodecs, HandMade16zTablesDecodeThroughTheTable) {
  // Table {0, 500, 4000}; index 1; 0x57: +1, -1; 0xE1: two repeats; 0x7D: -1, pad.
  const Bytes payload{0x03, 0x00, 0x00, 0x00, 0xF4, 0x01, 0xA0, 0x0F, 0x01, 0x00, 0x57, 0xE1, 0x7D};
  EXPECT_EQ(as16(decoded(oni::kCodec16zTables, payload, {3, 2, 2})),
            (std::vector<std::uint16_t>{500, 4000, 500, 500, 500, 0}));
  // 0x4D: index 1 + 2 = 3, one past the table (OpenNI2 would read the stream as a value).
  expect_refused(oni::kCodec16zTables, {0x03, 0x00, 0x00, 0x00, 0xF4, 0x01, 0xA0, 0x0F, 0x01, 0x00, 0x4D}, {2, 1, 2},
                 "byte 10: index 3 outside the table of 3 values");
  expect_refused(oni::kCodec16zTables, {0x03, 0x00, 0x00, 0x00, 0xF4, 0x01}, {1, 1, 2},
                 "16zT payload: byte 2: the payload ends inside the table of 3 values");
  expect_refused(oni::kCodec16zTables, {0x00, 0x00, 0x00, 0x00}, {1, 1, 2}, "index 0 outside the table of 0 values");
}

TEST(OniCodecs, HandMade8zDecodesAsWorkedOut) {
  // 100; 0x67: +0, -1; 0xE1: two repeats; F1 2F: whole 0x12, then whole 0xC8; 0x5D: +1, pad.
  const Bytes payload{100, 0x67, 0xE1, 0xF1, 0x2F, 0xC8, 0x5D};
  EXPECT_EQ(decoded(oni::kCodec8z, payload, {4, 2, 1}), (Bytes{100, 100, 99, 99, 99, 0x12, 0xC8, 0xC9}));
  EXPECT_EQ(encode_8z({100, 100, 99, 99, 99, 0x12, 0xC8, 0xC9}), payload);
}

TEST(OniCodecs, DepthWithRunsJumpsAndZerosRoundTrips) {
  const std::vector<std::uint16_t> depth = test_depth(64, 48);
  const Bytes z = encode_16z(depth);
  const Bytes t = encode_16z_tables(depth);
  EXPECT_LT(z.size(), depth.size() * 2);
  EXPECT_EQ(as16(decoded(oni::kCodec16z, z, kDepth64x48)), depth);
  EXPECT_EQ(as16(decoded(oni::kCodec16zTables, t, kDepth64x48)), depth);
  // A row of one value is runs: 0xEF (30 pixels) and the rest.
  const Bytes flat = encode_16z(std::vector<std::uint16_t>(64 * 48, 1234));
  EXPECT_LT(flat.size(), 120u);
  EXPECT_EQ(as16(decoded(oni::kCodec16z, flat, kDepth64x48)), std::vector<std::uint16_t>(64 * 48, 1234));
  // 8z over the bytes of the depth image, and over a colour ramp.
  Bytes bytes(depth.size() * 2);
  std::memcpy(bytes.data(), depth.data(), bytes.size());
  EXPECT_EQ(decoded(oni::kCodec8z, encode_8z(bytes), {64, 48, 2}), bytes);
  Bytes ramp(32 * 24 * 3);
  for (std::size_t k = 0; k < ramp.size(); ++k) ramp[k] = static_cast<std::uint8_t>(k % 3 == 0 ? k / 7 : k % 3 == 1 ? 200 : k * 13);
  EXPECT_EQ(decoded(oni::kCodec8z, encode_8z(ramp), {32, 24, 3}), ramp);
}

TEST(OniCodecs, PayloadsThatLieAreRefusedWithAReason) {
  const FrameShape five{5, 1, 2};
  const Bytes five16z = encode_16z({10, 11, 12, 100, 101});
  ASSERT_EQ(as16(decoded(oni::kCodec16z, five16z, five)), (std::vector<std::uint16_t>{10, 11, 12, 100, 101}));
  expect_refused(oni::kCodec16z, five16z, {6, 1, 2}, "16zP payload: decodes to 10 bytes, the frame needs 12");
  expect_refused(oni::kCodec16z, five16z, {4, 1, 2}, "a pixel past the frame of 4 pixels");
  expect_refused(oni::kCodec16z, {0xE8, 0x03, 0xEF}, {10, 1, 2}, "byte 2: the run of 30 pixels ends past the frame of 10 pixels");
  expect_refused(oni::kCodec16z, {0xE8, 0x03, 0xFF}, {2, 1, 2}, "byte 3: the payload ends inside an escape");
  expect_refused(oni::kCodec16z, {0xE8, 0x03, 0x6F, 0x12}, {3, 1, 2}, "byte 4: the payload ends inside an escape");
  expect_refused(oni::kCodec16z, {0xE8}, {1, 1, 2}, "the payload ends inside the first pixel");
  expect_refused(oni::kCodec16z, {}, {1, 1, 2}, "byte 0: the payload ends inside the first pixel");
  expect_refused(oni::kCodec16z, five16z, {5, 1, 3}, "no 16-bit pixels");
  expect_refused(oni::kCodec8z, {100, 0xF1}, {2, 1, 1}, "byte 2: the payload ends inside a whole pixel");
  expect_refused(oni::kCodec8z, {100, 0x6F}, {3, 1, 1}, "the payload ends inside a whole pixel");
  expect_refused(oni::kCodec8z, {100, 0xE2}, {3, 1, 1}, "byte 1: the run of 4 pixels ends past the frame of 3 pixels");
  expect_refused(oni::kCodec8z, {100, 0x66}, {2, 1, 1}, "byte 1: a pixel past the frame of 2 pixels");
  expect_refused(oni::kCodec8z, {100, 0x6D}, {3, 1, 1}, "Im8z payload: decodes to 2 bytes, the frame needs 3");
  expect_refused(oni::fourcc('X', 'Y', 'Z', 'W'), five16z, five, "XYZW payload: no decoder");
  expect_refused(oni::kCodec16z, five16z, {1600, 1200, 4}, "OpenNI2's player decodes 1 to 5760000");
  // Every truncation of a real frame is refused, whatever byte it ends at.
  const std::vector<std::uint16_t> depth = test_depth(64, 48);
  const std::map<std::uint32_t, Bytes> payloads{{oni::kCodec16z, encode_16z(depth)},
                                                {oni::kCodec16zTables, encode_16z_tables(depth)}};
  for (const auto& [codec, payload] : payloads) {
    for (std::size_t n = 0; n < payload.size(); ++n) {
      Bytes frame;
      const Bytes cut(payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(n));
      EXPECT_NE(oni::decode_frame(codec, cut.data(), cut.size(), kDepth64x48, frame), "") << n;
    }
  }
}

TEST(OniCodecs, GarbageNeverReadsOrWritesOutOfBounds) {
  // Random payloads, and a real payload with one byte changed: each decodes
  // or is refused; ASan (OFV_SANITIZE) sees any access outside.
  std::mt19937 random(11);
  const std::vector<std::uint16_t> depth = test_depth(64, 48);
  const Bytes real16z = encode_16z(depth), real16zT = encode_16z_tables(depth);
  int refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    for (const std::uint32_t codec : {oni::kCodec16z, oni::kCodec16zTables, oni::kCodec8z, oni::kCodecJpeg}) {
      Bytes payload;
      if (trial % 2 == 0 && codec != oni::kCodecJpeg) {
        payload = codec == oni::kCodec16zTables ? real16zT : real16z;
        payload[random() % payload.size()] = static_cast<std::uint8_t>(random());
      } else {
        payload.resize(random() % 64);
        for (std::uint8_t& b : payload) b = static_cast<std::uint8_t>(random());
        if (codec == oni::kCodecJpeg && payload.size() >= 4 && trial % 3 == 0) {
          payload[0] = 0xFF, payload[1] = 0xD8, payload[payload.size() - 2] = 0xFF, payload[payload.size() - 1] = 0xD9;
        }
      }
      Bytes frame;
      const FrameShape shape = codec == oni::kCodec8z ? FrameShape{64, 48, 2} : codec == oni::kCodecJpeg ? FrameShape{16, 8, 3} : kDepth64x48;
      const std::string why = oni::decode_frame(codec, payload.data(), payload.size(), shape, frame);
      refused += why.empty() ? 0 : 1;
      EXPECT_EQ(frame.size(), shape.bytes());
    }
  }
  EXPECT_GT(refused, 6000);
}

TEST(OniCodecs, JpegDecodesToTheNodesModeOnly) {
  cv::Mat bgr(8, 16, CV_8UC3, cv::Scalar(0, 0, 255));  // red, as OpenCV stores it
  bgr(cv::Rect(8, 0, 8, 8)).setTo(cv::Scalar(255, 0, 0));  // blue right half
  Bytes colour, grey;
  ASSERT_TRUE(cv::imencode(".jpg", bgr, colour, {cv::IMWRITE_JPEG_QUALITY, 95}));
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat(8, 16, CV_8UC1, cv::Scalar(77)), grey));
  const Bytes rgb = decoded(oni::kCodecJpeg, colour, {16, 8, 3});
  ASSERT_EQ(rgb.size(), 16u * 8 * 3);
  EXPECT_GT(rgb[0], 200);  // red first: RGB, as OpenNI2's libjpeg gives it
  EXPECT_LT(rgb[2], 50);
  EXPECT_GT(rgb[3 * 15 + 2], 200);
  const Bytes g = decoded(oni::kCodecJpeg, grey, {16, 8, 1});
  for (const std::uint8_t v : g) EXPECT_NEAR(v, 77, 2);
  expect_refused(oni::kCodecJpeg, colour, {8, 16, 3}, "a 16x8 JPEG of 3 components of 8 bits, the frame is 8x16 of 3");
  expect_refused(oni::kCodecJpeg, grey, {16, 8, 3}, "a 16x8 JPEG of 1 components");
  expect_refused(oni::kCodecJpeg, colour, {16, 8, 2}, "GRAY8 or RGB888 only");
  expect_refused(oni::kCodecJpeg, Bytes(colour.begin(), colour.begin() + static_cast<std::ptrdiff_t>(colour.size() / 2)),
                 {16, 8, 3}, "no JPEG end of image");
  expect_refused(oni::kCodecJpeg, {0xFF, 0xD8, 0xFF, 0xD9}, {16, 8, 3}, "no frame header before its scan");
  expect_refused(oni::kCodecJpeg, {0xFF, 0xD8, 0xFF, 0xE0, 0x40, 0x00, 0xFF, 0xD9}, {16, 8, 3},
                 "byte 2: a JPEG segment runs past the payload");
  // A header that fits but entropy-coded data that is not JPEG at all.
  Bytes broken(colour);
  for (std::size_t k = colour.size() - 40; k < colour.size() - 2; ++k) broken[k] = 0xFF;
  Bytes frame;
  const std::string why = oni::decode_frame(oni::kCodecJpeg, broken.data(), broken.size(), {16, 8, 3}, frame);
  SUCCEED() << "a JPEG with broken entropy data: '" << why << "' (libjpeg may fill in what it cannot read)";
}

// --- .oni files with compressed nodes ---------------------------------------

template <typename T>
T get(const std::string& s, std::size_t at) {
  T v;
  std::memcpy(&v, s.data() + at, sizeof(T));
  return v;
}
template <typename T>
void set(std::string& s, std::size_t at, T v) {
  std::memcpy(s.data() + at, &v, sizeof(T));
}

/// An OniWriter file with node `node`'s codec set to `codec` and each of its
/// frames' payloads replaced by `encode(frame index, uncompressed payload)`;
/// undo positions follow the records that moved. `payload_at` gets the offsets
/// of the new payloads.
std::string recode(const std::string& file, std::uint32_t node, std::uint32_t codec,
                   const std::function<Bytes(int, const Bytes&)>& encode, std::vector<std::size_t>& payload_at) {
  std::string out = file.substr(0, oni::kFileHeaderBytes);
  std::map<std::uint64_t, std::uint64_t> moved{{0, 0}};
  int frame = 0;
  for (std::size_t at = oni::kFileHeaderBytes; at + oni::kRecordHeaderBytes <= file.size();) {
    const auto type = get<std::uint32_t>(file, at + 4), id = get<std::uint32_t>(file, at + 8);
    const auto fields = get<std::uint32_t>(file, at + 12), payload = get<std::uint32_t>(file, at + 16);
    std::string record = file.substr(at, fields);
    std::string data = file.substr(at + fields, payload);
    set(record, 20, moved.at(get<std::uint64_t>(record, 20)));
    if (type == oni::kNodeAdded && id == node) {
      set(record, oni::kRecordHeaderBytes + 4 + get<std::uint32_t>(record, oni::kRecordHeaderBytes) + 4, codec);
    }
    if (type == oni::kNewData && id == node) {
      const Bytes compressed = encode(frame++, Bytes(data.begin(), data.end()));
      data.assign(compressed.begin(), compressed.end());
      set(record, 16, static_cast<std::uint32_t>(data.size()));
      payload_at.push_back(out.size() + record.size());
    }
    moved[at] = out.size();
    out += record + data;
    at += fields + payload;
    if (type == oni::kEnd) break;
  }
  return out;
}

std::vector<std::uint16_t> depth_of(const Bytes& payload) { return as16(payload); }

std::vector<RgbdFrame> three_frames(bool colour) {
  std::vector<RgbdFrame> frames;
  for (int k = 0; k < 3; ++k) {
    frames.push_back(test::table_and_case(Eigen::Vector3d(0.01 * k, 0.0, 0.0675))
                         .render(test::vga(160), test::front_camera(), nullptr, k / 30.0));
    if (!colour) frames.back().rgb.clear();
  }
  return frames;
}

std::string write_oni(const std::string& name, const std::vector<RgbdFrame>& frames) {
  const fs::path path = fs::path(test::scratch_dir()) / name;
  OniWriter writer(path.string());
  for (const RgbdFrame& f : frames) writer.write(f);
  writer.close();
  return path.string();
}

std::string spit(const std::string& name, const std::string& bytes) {
  const fs::path path = fs::path(test::scratch_dir()) / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path.string();
}

/// Every frame ofv's playback gives for `path`, checked against OpenNI2's own
/// player: the same depth (1 mm units) and colour, frame by frame.
std::vector<RgbdFrame> played(const std::string& path) {
  std::vector<RgbdFrame> frames;
  OpenNi2Source source(path);
  while (auto f = source.next()) frames.push_back(*f);
  const test::OpenNi2Playback theirs = test::play_with_openni2(path);
  EXPECT_EQ(theirs.depth.size(), frames.size()) << path;
  if (!frames.empty()) {
    EXPECT_EQ(frames[0].intrinsics.width, theirs.width) << path;
    EXPECT_EQ(frames[0].intrinsics.height, theirs.height) << path;
  }
  for (std::size_t k = 0; k < std::min(frames.size(), theirs.depth.size()); ++k) {
    EXPECT_EQ(test::depth_differences(frames[k].depth, theirs.depth[k]), 0u) << path << ": depth frame " << k << " is not OpenNI2's";
    if (!theirs.rgb.empty()) {
      EXPECT_EQ(frames[k].rgb, theirs.rgb[k]) << path << ": colour frame " << k << " is not OpenNI2's";
    }
  }
  return frames;
}

bool same_depth(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  }
  return true;
}

std::string refusal(const std::string& path) {
  try {
    check_oni_file(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(OniCodecs, CompressedDepthNodesPassTheCheckAndPlayAsInOpenNi2) {
  const std::string plain = write_oni("ofv_plain_depth.oni", three_frames(false));
  const std::vector<RgbdFrame> expected = played(plain);
  ASSERT_EQ(expected.size(), 3u);
  for (const std::uint32_t codec : {oni::kCodec16zTables, oni::kCodec16z}) {
    const std::string name = oni::codec_name(codec);
    std::vector<std::size_t> at;
    const std::string path = spit("ofv_" + name + ".oni", recode(file_text(plain), 1, codec, [&](int, const Bytes& p) {
      return codec == oni::kCodec16z ? encode_16z(depth_of(p)) : encode_16z_tables(depth_of(p));
    }, at));
    ASSERT_EQ(refusal(path), "") << name;
    EXPECT_LT(fs::file_size(path), fs::file_size(plain) / 2) << name;
    // Every depth back, as OpenNI2's own decoder gives it: the format is OpenNI2's.
    const std::vector<RgbdFrame> frames = played(path);
    ASSERT_EQ(frames.size(), expected.size()) << name;
    for (std::size_t k = 0; k < frames.size(); ++k) EXPECT_TRUE(same_depth(frames[k].depth, expected[k].depth)) << name << " frame " << k;

    // The second frame one pixel short: refused at its payload, as a decoding that falls short.
    std::vector<std::size_t> damaged_at;
    const std::string short_path = spit("ofv_" + name + "_short.oni", recode(file_text(plain), 1, codec, [&](int k, const Bytes& p) {
      std::vector<std::uint16_t> d = depth_of(p);
      if (k == 1) d.pop_back();
      return codec == oni::kCodec16z ? encode_16z(d) : encode_16z_tables(d);
    }, damaged_at));
    EXPECT_NE(refusal(short_path).find(short_path + ": offset " + std::to_string(damaged_at[1]) + ": " + name +
                                       " payload: decodes to 38398 bytes, the frame needs 38400"),
              std::string::npos)
        << refusal(short_path);
    EXPECT_THROW(OpenNi2Source source(short_path), std::invalid_argument);
  }
  // A 16zT index past its table (OpenNI2 would read outside the table): the third frame's first index.
  std::vector<std::size_t> at;
  std::string bytes = recode(file_text(plain), 1, oni::kCodec16zTables,
                             [&](int, const Bytes& p) { return encode_16z_tables(depth_of(p)); }, at);
  const std::size_t first_index = at[2] + 2 + 2 * get<std::uint16_t>(bytes, at[2]);
  set(bytes, first_index, std::uint16_t{0xFFFF});
  const std::string path = spit("ofv_16zT_index.oni", bytes);
  EXPECT_NE(refusal(path).find(path + ": offset " + std::to_string(at[2]) + ": 16zT payload: byte " +
                               std::to_string(first_index - at[2]) + ": index 65535 outside the table"),
            std::string::npos)
      << refusal(path);
}

TEST(OniCodecs, CompressedColourNodesPassTheCheckAndPlayAsInOpenNi2) {
  const std::string plain = write_oni("ofv_plain_colour.oni", three_frames(true));
  const std::vector<RgbdFrame> expected = played(plain);
  ASSERT_EQ(expected.size(), 3u);
  const int w = expected[0].intrinsics.width, h = expected[0].intrinsics.height;
  // Im8z: lossless.
  std::vector<std::size_t> at;
  const std::string z8 = spit("ofv_8z.oni", recode(file_text(plain), 2, oni::kCodec8z, [](int, const Bytes& p) { return encode_8z(p); }, at));
  ASSERT_EQ(refusal(z8), "");
  std::vector<RgbdFrame> frames = played(z8);
  ASSERT_EQ(frames.size(), expected.size());
  for (std::size_t k = 0; k < frames.size(); ++k) EXPECT_EQ(frames[k].rgb, expected[k].rgb) << "Im8z frame " << k;
  // JPEG: RGB close to the original (libjpeg, as in OpenNI2).
  const auto jpeg = [&](int, const Bytes& p) {
    cv::Mat bgr(h, w, CV_8UC3);
    for (std::size_t i = 0; i < p.size(); i += 3) {
      for (std::size_t c = 0; c < 3; ++c) bgr.data[i + c] = p[i + 2 - c];
    }
    Bytes out;
    cv::imencode(".jpg", bgr, out, {cv::IMWRITE_JPEG_QUALITY, 98});
    return out;
  };
  at.clear();
  const std::string jpg = spit("ofv_jpeg.oni", recode(file_text(plain), 2, oni::kCodecJpeg, jpeg, at));
  ASSERT_EQ(refusal(jpg), "");
  frames = played(jpg);
  ASSERT_EQ(frames.size(), expected.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    double error = 0.0;
    for (std::size_t i = 0; i < frames[k].rgb.size(); ++i) error += std::abs(frames[k].rgb[i] - expected[k].rgb[i]);
    EXPECT_LT(error / static_cast<double>(frames[k].rgb.size()), 4.0) << "JPEG frame " << k;
  }
  // A JPEG of the wrong size, and one cut short: refused at the payload.
  for (const bool cut : {false, true}) {
    at.clear();
    const std::string path = spit("ofv_jpeg_bad.oni", recode(file_text(plain), 2, oni::kCodecJpeg, [&](int k, const Bytes& p) {
      Bytes out = jpeg(k, p);
      if (k == 2 && cut) out.resize(out.size() - 100);
      if (k == 2 && !cut) cv::imencode(".jpg", cv::Mat(h, w / 2, CV_8UC3, cv::Scalar(1, 2, 3)), out);
      return out;
    }, at));
    EXPECT_NE(refusal(path).find(path + ": offset " + std::to_string(at[2]) + ": JPEG payload: "), std::string::npos)
        << refusal(path);
  }
}

/// The offset of the value of node `node`'s property `name` (type `type`) in an OniWriter file.
std::size_t property_value_at(const std::string& file, std::uint32_t node, std::uint32_t type, const std::string& name) {
  for (std::size_t at = oni::kFileHeaderBytes; at + oni::kRecordHeaderBytes <= file.size();) {
    const auto fields = get<std::uint32_t>(file, at + 12), payload = get<std::uint32_t>(file, at + 16);
    const std::size_t name_at = at + oni::kRecordHeaderBytes + 4;
    if (get<std::uint32_t>(file, at + 4) == type && get<std::uint32_t>(file, at + 8) == node &&
        file.compare(name_at, name.size() + 1, name.c_str(), name.size() + 1) == 0) {
      return name_at + name.size() + 1 + 4;  // past the name and the value's size
    }
    at += fields + payload;
  }
  ADD_FAILURE() << "no property " << name << " of node " << node;
  return 0;
}

TEST(OniCodecs, ACroppedDepthNodePlaysItsWindowAsInOpenNi2) {
  const std::vector<RgbdFrame> full = three_frames(false);
  const std::string plain = write_oni("ofv_plain_uncropped.oni", full);
  const int w = full[0].intrinsics.width;
  // The depth node cropped to the 60 x 40 window at (30, 20): its frames hold that window only.
  std::string bytes = file_text(plain);
  const std::size_t cropping = property_value_at(bytes, 1, oni::kGeneralProperty, "xnCropping");
  set(bytes, cropping, std::uint32_t{1});
  for (const auto& [k, v] : std::vector<std::pair<int, std::uint16_t>>{{0, 30}, {1, 20}, {2, 60}, {3, 40}}) {
    set(bytes, cropping + 4 + 2 * k, v);
  }
  set(bytes, property_value_at(bytes, 1, oni::kIntProperty, "oniRequiredFrameSize"), std::uint64_t{60 * 40 * 2});
  std::vector<std::size_t> at;
  const std::string path = spit("ofv_cropped.oni", recode(bytes, 1, oni::kCodecUncompressed, [&](int, const Bytes& p) {
    Bytes window;
    for (int v = 20; v < 60; ++v) window.insert(window.end(), p.begin() + 2 * (v * w + 30), p.begin() + 2 * (v * w + 90));
    return window;
  }, at));
  ASSERT_EQ(refusal(path), "");
  const std::vector<RgbdFrame> frames = played(path);  // as OpenNI2 plays it, pixel for pixel
  ASSERT_EQ(frames.size(), full.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const RgbdFrame& f = frames[k];
    ASSERT_EQ(f.intrinsics.width, 60);
    ASSERT_EQ(f.intrinsics.height, 40);
    // The same camera: the principal point moves with the window, the focal lengths stay.
    EXPECT_NEAR(f.intrinsics.fx, full[k].intrinsics.fx, 1e-3);
    EXPECT_NEAR(f.intrinsics.cx, 0.5 * w - 30, 1e-9);
    EXPECT_NEAR(f.intrinsics.cy, 0.5 * full[k].intrinsics.height - 20, 1e-9);
    for (int v = 0; v < 40; ++v) {
      for (int u = 0; u < 60; ++u) {
        ASSERT_NEAR(f.depth[f.index(u, v)], full[k].depth[full[k].index(u + 30, v + 20)], 0.0005 + 1e-6)
            << "frame " << k << " pixel " << u << ", " << v;
      }
    }
  }
}

}  // namespace
}  // namespace ofv
