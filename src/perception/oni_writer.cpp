// .oni writer: the OpenNI2 record format (oni_format.h), uncompressed frames.
// Per node: NODE_ADDED and its properties (video mode, pixel format, field of
// view, cropping - the player drops frames of a node without cropping); then
// per node NODE_STATE_READY and NODE_DATA_BEGIN; then NEW_DATA records; END
// closes the file.
#include "ofv/sources/openni2_source.h"

#include "ofv/perception/cloud.h"
#include "oni_format.h"

#include <OniCEnums.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>

namespace ofv {

namespace {

using namespace oni;
constexpr std::uint32_t kXnPixelFormatRgb24 = 1;
constexpr std::uint32_t kXnPixelFormatGray16 = 4;

/// One record being assembled: header, fields, payload.
class Record {
 public:
  Record(std::uint32_t type, std::uint32_t node, std::uint64_t undo)
      : bytes_(kRecordHeaderBytes, 0) {
    put_at(0, kRecordMagic);
    put_at(4, type);
    put_at(8, node);
    put_at(20, undo);
  }
  template <typename T>
  Record& field(const T& value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
    return *this;
  }
  Record& string(const char* s) {
    const auto n = static_cast<std::uint32_t>(std::strlen(s) + 1);
    field(n);
    bytes_.insert(bytes_.end(), s, s + n);
    return *this;
  }
  Record& bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + n);
    return *this;
  }
  /// Writes the record with `payload` after its fields.
  void write(std::ofstream& out, const void* payload = nullptr, std::size_t payload_bytes = 0) {
    put_at(12, static_cast<std::uint32_t>(bytes_.size()));
    put_at(16, static_cast<std::uint32_t>(payload_bytes));
    out.write(reinterpret_cast<const char*>(bytes_.data()),
              static_cast<std::streamsize>(bytes_.size()));
    if (payload_bytes > 0) {
      out.write(static_cast<const char*>(payload), static_cast<std::streamsize>(payload_bytes));
    }
  }

 private:
  template <typename T>
  void put_at(std::size_t offset, T value) {
    std::memcpy(bytes_.data() + offset, &value, sizeof(T));
  }
  std::vector<std::uint8_t> bytes_;
};

void write_file_header(std::ofstream& out, std::uint32_t max_node_id) {
  const std::uint8_t identity[4] = {'N', 'I', '1', '0'};
  const std::uint8_t major = 1, minor = 0;
  const std::uint16_t maintenance = 1;
  const std::uint32_t build = 0;
  const std::uint64_t max_timestamp = std::numeric_limits<std::uint64_t>::max();
  out.write(reinterpret_cast<const char*>(identity), 4);
  out.write(reinterpret_cast<const char*>(&major), 1);
  out.write(reinterpret_cast<const char*>(&minor), 1);
  out.write(reinterpret_cast<const char*>(&maintenance), 2);
  out.write(reinterpret_cast<const char*>(&build), 4);
  out.write(reinterpret_cast<const char*>(&max_timestamp), 8);
  out.write(reinterpret_cast<const char*>(&max_node_id), 4);
}

}  // namespace

OniWriter::OniWriter(const std::string& path, int fps) : path_(path), fps_(fps) {
  if (fps <= 0) {
    throw std::invalid_argument("OniWriter " + path + ": fps " + std::to_string(fps) +
                                ": expected > 0");
  }
  // A device or a directory at `path` would get its poses file beside it.
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec)) {
    throw std::invalid_argument(path + ": exists and is not a regular file: give a new .oni file");
  }
  out_.open(path, std::ios::binary | std::ios::trunc);
  if (!out_) {
    throw std::runtime_error(path + ": cannot create the .oni file");
  }
  poses_.open(path + ".poses.txt", std::ios::trunc);
  poses_ << "# camera pose wMc of each frame of " << path << "\n# timestamp tx ty tz qx qy qz qw\n";
  depth_.id = 1;
  image_.id = 2;
}

OniWriter::~OniWriter() {
  try {
    close();
  } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw
  }
}

void OniWriter::write_node_added(const Node& node, bool depth, std::uint32_t frames,
                                 std::uint64_t max_time) {
  Record(kNodeAdded, node.id, 0)
      .string(depth ? "Depth" : "Image")
      .field(depth ? kNodeTypeDepth : kNodeTypeImage)
      .field(kCodecUncompressed)
      .field(frames)
      .field(std::uint64_t{0})  // min timestamp
      .field(max_time)
      .field(std::uint64_t{0})  // no seek table
      .write(out_);
}

void OniWriter::write_node_header(Node& node, bool depth, const CameraIntrinsics& k) {
  node.added_position = static_cast<std::uint64_t>(out_.tellp());
  write_node_added(node, depth, std::numeric_limits<std::uint32_t>::max(),
                   std::numeric_limits<std::uint64_t>::max());
  const auto w = static_cast<std::uint32_t>(k.width);
  const auto h = static_cast<std::uint32_t>(k.height);
  const auto int_property = [&](const char* name, std::uint64_t value) {
    Record(kIntProperty, node.id, 0).string(name).field(std::uint32_t{8}).field(value).write(out_);
  };
  const auto general_property = [&](const char* name, const void* data, std::uint32_t bytes) {
    Record(kGeneralProperty, node.id, 0).string(name).field(bytes).bytes(data, bytes).write(out_);
  };
  const std::uint32_t bytes_per_pixel = depth ? 2 : 3;
  int_property("oniRequiredFrameSize", std::uint64_t{w} * h * bytes_per_pixel);
  int_property("xnIsGenerating", 1);
  if (depth) {
    int_property("xnDeviceMaxDepth", 10000);
  }
  const std::uint32_t mode[3] = {w, h, static_cast<std::uint32_t>(fps_)};
  int_property("xnSupportedMapOutputModesCount", 1);
  general_property("xnSupportedMapOutputModes", mode, sizeof mode);
  general_property("xnMapOutputMode", mode, sizeof mode);
  const std::uint32_t xn_format = depth ? kXnPixelFormatGray16 : kXnPixelFormatRgb24;
  const std::uint32_t supported = 1u << (xn_format - 1);  // bit field, RGB24 first
  general_property("xnSupportedPixelFormats", &supported, sizeof supported);
  int_property("xnPixelFormat", xn_format);
  int_property("oniPixelFormat", depth ? ONI_PIXEL_FORMAT_DEPTH_1_MM : ONI_PIXEL_FORMAT_RGB888);
  const double fov[2] = {2.0 * std::atan(0.5 * k.width / k.fx),
                         2.0 * std::atan(0.5 * k.height / k.fy)};
  general_property("xnFOV", fov, sizeof fov);
  int_property("Cropping", 1);
#pragma pack(push, 1)
  struct {
    std::int32_t enabled;
    std::uint16_t x, y, width, height;
  } cropping{0, 0, 0, static_cast<std::uint16_t>(w), static_cast<std::uint16_t>(h)};
#pragma pack(pop)
  general_property("xnCropping", &cropping, sizeof cropping);
}

void OniWriter::write_data_begin(const Node& node) {
  Record(kNodeStateReady, node.id, 0).write(out_);
  Record(kNodeDataBegin, node.id, 0)
      .field(std::numeric_limits<std::uint32_t>::max())
      .field(std::numeric_limits<std::uint64_t>::max())
      .write(out_);
}

void OniWriter::write_frame(Node& node, std::uint64_t timestamp_us, const void* data,
                            std::size_t bytes) {
  const auto position = static_cast<std::uint64_t>(out_.tellp());
  Record(kNewData, node.id, node.last_data_position)
      .field(timestamp_us)
      .field(static_cast<std::uint32_t>(count_ + 1))  // frame ids start at 1
      .write(out_, data, bytes);
  node.last_data_position = position;
}

void OniWriter::write(const RgbdFrame& frame) {
  if (closed_) {
    throw std::logic_error("OniWriter " + path_ + ": write after close");
  }
  check_frame(frame);
  const CameraIntrinsics& k = frame.intrinsics;
  const auto time_us =
      static_cast<std::uint64_t>(std::llround(std::max(0.0, frame.timestamp) * 1e6));
  if (count_ == 0) {
    intrinsics_ = k;
    has_colour_ = !frame.rgb.empty();
    first_time_us_ = time_us;
    write_file_header(out_, has_colour_ ? 2 : 1);
    write_node_header(depth_, true, k);
    if (has_colour_) {
      write_node_header(image_, false, k);
    }
    // The player learns the nodes from the records before the first
    // DATA_BEGIN: every node is added before any begins its data.
    write_data_begin(depth_);
    if (has_colour_) {
      write_data_begin(image_);
    }
  } else {
    if (k.width != intrinsics_.width || k.height != intrinsics_.height) {
      throw std::invalid_argument(
          "OniWriter " + path_ + ": frame " + std::to_string(count_) + " is " +
          std::to_string(k.width) + "x" + std::to_string(k.height) + ", the recording " +
          std::to_string(intrinsics_.width) + "x" + std::to_string(intrinsics_.height));
    }
    if (frame.rgb.empty() == has_colour_) {
      throw std::invalid_argument(
          "OniWriter " + path_ + ": frame " + std::to_string(count_) +
          (has_colour_ ? " has no colour" : " has colour, the first had none"));
    }
    if (time_us < last_time_us_) {
      throw std::invalid_argument("OniWriter " + path_ + ": timestamps go backwards at frame " +
                                  std::to_string(count_));
    }
  }
  const std::uint64_t relative = time_us - first_time_us_;
  depth_buffer_.resize(frame.depth.size());
  for (std::size_t i = 0; i < frame.depth.size(); ++i) {
    const double mm = std::round(static_cast<double>(frame.depth[i]) * 1000.0);
    depth_buffer_[i] =
        std::isfinite(mm) && mm > 0.0 && mm <= 65535.0 ? static_cast<std::uint16_t>(mm) : 0;
  }
  write_frame(depth_, relative, depth_buffer_.data(), depth_buffer_.size() * 2);
  if (has_colour_) {
    write_frame(image_, relative, frame.rgb.data(), frame.rgb.size());
  }
  poses_ << format_pose_line(frame.timestamp, frame.wMc);
  last_time_us_ = time_us;
  ++count_;
  if (!out_ || !poses_) {
    throw std::runtime_error(path_ + ": write failed");
  }
}

void OniWriter::close() {
  if (closed_) {
    return;
  }
  closed_ = true;
  if (count_ == 0) {
    write_file_header(out_, 0);
  }
  Record(kEnd, 0, 0).write(out_);
  const std::uint64_t end = static_cast<std::uint64_t>(out_.tellp());
  // The player takes the frame count of each node from its NODE_ADDED record.
  const std::uint64_t max_time = last_time_us_ - first_time_us_;
  if (count_ > 0) {
    out_.seekp(static_cast<std::streamoff>(depth_.added_position));
    write_node_added(depth_, true, static_cast<std::uint32_t>(count_), max_time);
    if (has_colour_) {
      out_.seekp(static_cast<std::streamoff>(image_.added_position));
      write_node_added(image_, false, static_cast<std::uint32_t>(count_), max_time);
    }
    out_.seekp(static_cast<std::streamoff>(end));
  }
  out_.close();
  poses_.close();
  if (out_.fail()) {
    throw std::runtime_error(path_ + ": cannot finish the .oni file");
  }
}

}  // namespace ofv
