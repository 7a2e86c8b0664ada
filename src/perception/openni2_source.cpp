// OpenNI2 devices and .oni recordings (OpenNI 2.2 C++ API).
#include "ofv/sources/openni2_source.h"

#include <OpenNI.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace fs = std::filesystem;

namespace ofv {

namespace {

/// OpenNI2 is initialised once per process and never shut down: shutting
/// down while another source lives would pull its drivers away.
void initialise_openni() {
  static std::once_flag once;
  static openni::Status status = openni::STATUS_OK;
  static std::string error;
  std::call_once(once, [] {
    status = openni::OpenNI::initialize();
    error = openni::OpenNI::getExtendedError();
  });
  if (status != openni::STATUS_OK) {
    throw std::runtime_error("OpenNI2 cannot initialise: " + error);
  }
}

/// OpenNI2's extended error on one line (it comes tab-indented, one line per layer).
std::string last_error() {
  std::string e;
  for (const char* c = openni::OpenNI::getExtendedError(); *c != '\0'; ++c) {
    const bool space = *c == '\n' || *c == '\t' || *c == '\r' || *c == ' ';
    if (!space) {
      e += *c;
    } else if (!e.empty() && e.back() != ' ') {
      e += ' ';
    }
  }
  while (!e.empty() && e.back() == ' ') {
    e.pop_back();
  }
  return e.empty() ? "unknown OpenNI2 error" : e;
}

bool looks_like_file(const std::string& uri) {
  return uri.size() > 4 && uri.compare(uri.size() - 4, 4, ".oni") == 0;
}

}  // namespace

struct OpenNi2Source::Impl {
  openni::Device device;
  openni::VideoStream depth;
  openni::VideoStream colour;
  bool has_colour = false;
  bool file = false;
  int frames = 0;  // depth frames in a recording
  int read = 0;    // depth frames read so far
  std::vector<StampedPose> poses;
  double first_timestamp = -1.0;

  ~Impl() {
    if (depth.isValid()) {
      depth.stop();
    }
    if (colour.isValid()) {
      colour.stop();
    }
    // Some drivers (DummyDevice) do not join their threads on stop():
    // destroying right away can crash (PLATFORM-NOTES).
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    depth.destroy();
    colour.destroy();
    device.close();
  }
};

OpenNi2Source::OpenNi2Source(const std::string& uri, const OpenNi2Options& options)
    : uri_(uri), options_(options) {
  rewind();
}

OpenNi2Source::~OpenNi2Source() = default;

void OpenNi2Source::rewind() {
  impl_.reset();
  if (looks_like_file(uri_) && !fs::is_regular_file(uri_)) {
    throw std::runtime_error(uri_ + ": no such .oni file");
  }
  if (looks_like_file(uri_)) {
    check_oni_file(uri_);  // OpenNI2 never sees a malformed record
  }
  initialise_openni();
  auto impl = std::make_unique<Impl>();
  if (impl->device.open(uri_.empty() ? openni::ANY_DEVICE : uri_.c_str()) != openni::STATUS_OK) {
    throw std::runtime_error((uri_.empty() ? std::string("first OpenNI2 device") : uri_) +
                             ": cannot open the OpenNI2 device or recording: " + last_error());
  }
  impl->file = impl->device.isFile();
  if (!impl->device.hasSensor(openni::SENSOR_DEPTH) ||
      impl->depth.create(impl->device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    throw std::runtime_error(uri_ + ": no depth stream: " + last_error());
  }
  if (options_.colour && impl->device.hasSensor(openni::SENSOR_COLOR) &&
      impl->colour.create(impl->device, openni::SENSOR_COLOR) == openni::STATUS_OK) {
    impl->has_colour = true;
  }
  if (impl->file) {
    openni::PlaybackControl* playback = impl->device.getPlaybackControl();
    playback->setRepeatEnabled(false);
    playback->setSpeed(options_.playback_speed);
    impl->frames = playback->getNumberOfFrames(impl->depth);
    const std::string poses = uri_ + ".poses.txt";
    if (fs::exists(poses)) {
      impl->poses = read_pose_file(poses);
      if (impl->poses.size() < static_cast<std::size_t>(impl->frames)) {
        throw std::invalid_argument(poses + ": " + std::to_string(impl->poses.size()) + " poses for " +
                                    std::to_string(impl->frames) + " frames");
      }
    }
  } else {
    if (options_.registration && impl->has_colour &&
        impl->device.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
      impl->device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
    }
    if (impl->has_colour) {
      impl->device.setDepthColorSyncEnabled(true);
    }
  }
  if (impl->depth.start() != openni::STATUS_OK) {
    throw std::runtime_error(uri_ + ": cannot start the depth stream: " + last_error());
  }
  if (impl->has_colour && impl->colour.start() != openni::STATUS_OK) {
    throw std::runtime_error(uri_ + ": cannot start the colour stream: " + last_error());
  }
  impl_ = std::move(impl);
}

bool OpenNi2Source::is_file() const { return impl_->file; }

int OpenNi2Source::number_of_frames() const { return impl_->frames; }

std::string OpenNi2Source::describe() const {
  return impl_->file
             ? "OpenNI2 recording " + uri_ + " (" + std::to_string(impl_->frames) + " frames)"
             : "OpenNI2 device " + uri_;
}

namespace {

/// Waits for one frame of `stream` and reads it; false on timeout.
bool read_frame(openni::VideoStream& stream, openni::VideoFrameRef& frame, int timeout_ms) {
  openni::VideoStream* streams[] = {&stream};
  int ready = -1;
  if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, timeout_ms) != openni::STATUS_OK) {
    return false;
  }
  return stream.readFrame(&frame) == openni::STATUS_OK && frame.isValid();
}

}  // namespace

std::optional<RgbdFrame> OpenNi2Source::next() {
  Impl& s = *impl_;
  if (s.file && s.read >= s.frames) {
    return std::nullopt;
  }
  openni::VideoFrameRef depth;
  if (!read_frame(s.depth, depth, options_.timeout_ms)) {
    throw std::runtime_error(uri_ + ": no depth frame within " +
                             std::to_string(options_.timeout_ms) + " ms: " + last_error());
  }
  ++s.read;
  const auto depth_scale = [](openni::PixelFormat format) {
    return format == openni::PIXEL_FORMAT_DEPTH_1_MM ? 1e-3 : format == openni::PIXEL_FORMAT_DEPTH_100_UM ? 1e-4 : 0.0;
  };
  const double scale = depth_scale(depth.getVideoMode().getPixelFormat());
  if (scale == 0.0) {
    const std::string why = uri_ + ": unsupported depth pixel format " +
                            std::to_string(static_cast<int>(depth.getVideoMode().getPixelFormat()));
    // A stream set to depth that hands over another format has had a glitch
    // (OpenNI2's DummyDevice once gave its depth stream a colour frame on a
    // loaded machine): that frame is bad, not the device.
    if (depth_scale(s.depth.getVideoMode().getPixelFormat()) != 0.0) throw BadFrame(why);
    throw std::runtime_error(why);
  }
  const int w = depth.getWidth();
  const int h = depth.getHeight();
  RgbdFrame f;
  if (options_.intrinsics) {
    f.intrinsics = *options_.intrinsics;
    if (f.intrinsics.width != w || f.intrinsics.height != h) {
      throw BadFrame(uri_ + ": a frame is " + std::to_string(w) + "x" +
                               std::to_string(h) + ", the given intrinsics " +
                               std::to_string(f.intrinsics.width) + "x" +
                               std::to_string(f.intrinsics.height));
    }
  } else {
    f.intrinsics.width = w;
    f.intrinsics.height = h;
    f.intrinsics.fx = 0.5 * w / std::tan(0.5 * s.depth.getHorizontalFieldOfView());
    f.intrinsics.fy = 0.5 * h / std::tan(0.5 * s.depth.getVerticalFieldOfView());
    f.intrinsics.cx = 0.5 * w;
    f.intrinsics.cy = 0.5 * h;
    if (!std::isfinite(f.intrinsics.fx) || !std::isfinite(f.intrinsics.fy) ||
        !(f.intrinsics.fx > 0.0) || !(f.intrinsics.fy > 0.0)) {
      throw std::runtime_error(uri_ +
                               ": the depth stream reports no usable field of view; "
                               "give the intrinsics");
    }
  }
  const double t = static_cast<double>(depth.getTimestamp()) * 1e-6;
  if (s.first_timestamp < 0.0) {
    s.first_timestamp = t;
  }
  f.timestamp = t - s.first_timestamp;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (depth.getData() == nullptr || depth.getStrideInBytes() < static_cast<int>(w * sizeof(openni::DepthPixel)) ||
      static_cast<std::size_t>(depth.getDataSize()) < static_cast<std::size_t>(depth.getStrideInBytes()) * h) {
    throw BadFrame(uri_ + ": a depth frame of " + std::to_string(depth.getDataSize()) + " bytes for " +
                   std::to_string(w) + "x" + std::to_string(h) + " pixels (a short read)");
  }
  f.depth.resize(n);
  const auto* bytes = static_cast<const std::uint8_t*>(depth.getData());
  for (int v = 0; v < h; ++v) {
    const auto* row = reinterpret_cast<const openni::DepthPixel*>(
        bytes + static_cast<std::size_t>(v) * static_cast<std::size_t>(depth.getStrideInBytes()));
    for (int u = 0; u < w; ++u) {
      f.depth[f.index(u, v)] = static_cast<float>(row[u] * scale);
    }
  }
  if (s.has_colour) {
    openni::VideoFrameRef colour;
    if (!read_frame(s.colour, colour, options_.timeout_ms)) {
      throw std::runtime_error(uri_ + ": no colour frame within " +
                               std::to_string(options_.timeout_ms) + " ms: " + last_error());
    }
    if (colour.getVideoMode().getPixelFormat() != openni::PIXEL_FORMAT_RGB888) {
      throw std::runtime_error(
          uri_ + ": unsupported colour pixel format " +
          std::to_string(static_cast<int>(colour.getVideoMode().getPixelFormat())));
    }
    const int cw = colour.getWidth();
    const int ch = colour.getHeight();
    const auto* cbytes = static_cast<const std::uint8_t*>(colour.getData());
    f.rgb.resize(3 * n);
    for (int v = 0; v < h; ++v) {
      const int cv = v * ch / h;  // nearest neighbour when the sizes differ
      const std::uint8_t* row = cbytes + static_cast<std::size_t>(cv) *
                                             static_cast<std::size_t>(colour.getStrideInBytes());
      for (int u = 0; u < w; ++u) {
        const int cu = u * cw / w;
        std::copy_n(row + 3 * cu, 3,
                    f.rgb.begin() + static_cast<std::ptrdiff_t>(3 * f.index(u, v)));
      }
    }
  }
  if (!s.poses.empty()) {
    // Frame i of a recording made by OniWriter has pose line i.
    const auto i = static_cast<std::size_t>(s.read - 1);
    f.wMc = s.poses[std::min(i, s.poses.size() - 1)].wMc;  // as many poses as frames (rewind)
  }
  return f;
}

}  // namespace ofv
