// OpenNI2 devices (OpenNI 2.2 C++ API) and .oni recordings, which ofv plays
// itself from the record format (oni_player.h) rather than through OpenNI2's
// player, libOniFile. That player's thread walks the device's stream list
// without a lock while a stream is destroyed, and is still at work for a
// while after stop(): closing the device right after stop() crashed it ten
// times in ten, and destroying the streams 50 ms after stop() crashed a CI
// run once in its 251 plays of one test. Its seek crashes too. The walk that
// checks every recording (check_oni_file) indexes it on the way.
#include "ofv/sources/openni2_source.h"

#include "oni_player.h"

#include <OpenNI.h>

#include <chrono>
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

/// A live OpenNI2 device and its streams.
struct Device {
  openni::Device device;
  openni::VideoStream depth;
  openni::VideoStream colour;
  bool has_colour = false;

  bool depth_started = false;
  bool colour_started = false;

  ~Device() {
    // DummyDevice's stream thread marks itself running when it first runs,
    // after start() returned: a stop() before that is lost, and the thread
    // then delivers frames to a destroyed stream (a crash, or another
    // stream's frame in a stream created later at the same address; seen
    // in 31 of 40 runs of a source closed before its first frame, with the
    // machine loaded). A frame from each started stream proves its thread
    // runs: wait for one (at most a second) before stopping it.
    stop(depth, depth_started);
    stop(colour, colour_started);
    // Nor does it join its threads on stop(): destroying right away can
    // crash (PLATFORM-NOTES). Once per device opened; 200 ms rather than
    // the 50 ms that sufficed on an idle machine, since a loaded one can
    // starve the driver's thread that long.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    depth.destroy();
    colour.destroy();
    device.close();
  }

  static void stop(openni::VideoStream& stream, bool started) {
    if (!started) return;
    openni::VideoStream* streams[] = {&stream};
    int ready = -1;
    (void)openni::OpenNI::waitForAnyStream(streams, 1, &ready, 1000);
    stream.stop();
  }
};

}  // namespace

struct OpenNi2Source::Impl {
  std::unique_ptr<Device> live;
  std::unique_ptr<oni::Player> recording;
  std::vector<StampedPose> poses;
  std::size_t next = 0;  // a recording's next depth frame
  double first_timestamp = -1.0;
  std::chrono::steady_clock::time_point started;  // of a paced playback
};

OpenNi2Source::OpenNi2Source(const std::string& uri, const OpenNi2Options& options)
    : uri_(uri), options_(options) {
  impl_ = std::make_unique<Impl>();
  if (looks_like_file(uri_)) {
    open_recording();
  } else {
    open_device();
  }
}

OpenNi2Source::~OpenNi2Source() = default;

void OpenNi2Source::open_recording() {
  if (!fs::is_regular_file(uri_)) {
    throw std::runtime_error(uri_ + ": no such .oni file");
  }
  std::uint64_t size = 0;
  std::unique_ptr<std::istream> file = oni::open_oni_file(uri_, size);
  auto rec = std::make_unique<oni::Player>(std::move(file), size, uri_, options_.colour);  // never plays a malformed record
  const std::string poses = uri_ + ".poses.txt";
  if (fs::exists(poses)) {
    impl_->poses = read_pose_file(poses);
    if (impl_->poses.size() < rec->frames()) {
      throw std::invalid_argument(poses + ": " + std::to_string(impl_->poses.size()) + " poses for " +
                                  std::to_string(rec->frames()) + " frames");
    }
  }
  impl_->recording = std::move(rec);
}

void OpenNi2Source::open_device() {
  initialise_openni();
  auto dev = std::make_unique<Device>();
  if (dev->device.open(uri_.empty() ? openni::ANY_DEVICE : uri_.c_str()) != openni::STATUS_OK) {
    throw std::runtime_error((uri_.empty() ? std::string("first OpenNI2 device") : uri_) +
                             ": cannot open the OpenNI2 device or recording: " + last_error());
  }
  if (!dev->device.hasSensor(openni::SENSOR_DEPTH) ||
      dev->depth.create(dev->device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    throw std::runtime_error(uri_ + ": no depth stream: " + last_error());
  }
  if (options_.colour && dev->device.hasSensor(openni::SENSOR_COLOR) &&
      dev->colour.create(dev->device, openni::SENSOR_COLOR) == openni::STATUS_OK) {
    dev->has_colour = true;
  }
  if (options_.registration && dev->has_colour &&
      dev->device.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
    dev->device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
  }
  if (dev->has_colour) {
    dev->device.setDepthColorSyncEnabled(true);
  }
  if (dev->depth.start() != openni::STATUS_OK) {
    throw std::runtime_error(uri_ + ": cannot start the depth stream: " + last_error());
  }
  dev->depth_started = true;
  if (dev->has_colour && dev->colour.start() != openni::STATUS_OK) {
    throw std::runtime_error(uri_ + ": cannot start the colour stream: " + last_error());
  }
  dev->colour_started = dev->has_colour;
  impl_->live = std::move(dev);
}

void OpenNi2Source::rewind() {
  if (impl_->recording) {
    impl_->next = 0;
    impl_->first_timestamp = -1.0;
  }
}

bool OpenNi2Source::is_file() const { return impl_->recording != nullptr; }

int OpenNi2Source::number_of_frames() const {
  return impl_->recording ? static_cast<int>(impl_->recording->frames()) : 0;
}

std::string OpenNi2Source::describe() const {
  return impl_->recording ? "OpenNI2 recording " + uri_ + " (" + std::to_string(number_of_frames()) + " frames)"
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
  std::optional<RgbdFrame> f = impl_->recording ? next_recorded() : next_live();
  if (!f) return f;
  if (impl_->first_timestamp < 0.0) {
    impl_->first_timestamp = f->timestamp;
  }
  f->timestamp -= impl_->first_timestamp;
  return f;
}

std::optional<RgbdFrame> OpenNi2Source::next_recorded() {
  Impl& s = *impl_;
  oni::Player& rec = *s.recording;
  if (s.next >= rec.frames()) {
    return std::nullopt;
  }
  if (options_.playback_speed > 0.0f) {
    // Paced like the sensor was: frame k is due (its time - the first's) /
    // speed after the first; frames already past due give way to the last
    // one due, as a live stream's would to a consumer that fell behind.
    const auto due = [&](std::size_t k) {
      const double after = static_cast<double>(rec.time_us(k) - rec.time_us(0)) * 1e-6 / options_.playback_speed;
      return s.started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(after));
    };
    if (s.next == 0) s.started = std::chrono::steady_clock::now();
    const auto now = std::chrono::steady_clock::now();
    while (s.next + 1 < rec.frames() && due(s.next + 1) <= now) ++s.next;
    std::this_thread::sleep_until(due(s.next));
  }
  const std::size_t k = s.next++;
  RgbdFrame f = rec.frame(k, options_.intrinsics);
  if (!s.poses.empty()) {
    f.wMc = s.poses[k].wMc;  // frame k of a recording made by OniWriter has pose line k
  }
  return f;
}

std::optional<RgbdFrame> OpenNi2Source::next_live() {
  Device& s = *impl_->live;
  openni::VideoFrameRef depth;
  if (!read_frame(s.depth, depth, options_.timeout_ms)) {
    throw std::runtime_error(uri_ + ": no depth frame within " +
                             std::to_string(options_.timeout_ms) + " ms: " + last_error());
  }
  const double scale = oni::depth_scale(depth.getVideoMode().getPixelFormat());
  if (scale == 0.0) {
    const std::string why = uri_ + ": unsupported depth pixel format " +
                            std::to_string(static_cast<int>(depth.getVideoMode().getPixelFormat()));
    // A stream set to depth that hands over another format has had a glitch
    // (OpenNI2's DummyDevice once gave its depth stream a colour frame on a
    // loaded machine): that frame is bad, not the device.
    if (oni::depth_scale(s.depth.getVideoMode().getPixelFormat()) != 0.0) throw BadFrame(why);
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
    f.intrinsics = oni::intrinsics_from_fov(uri_, s.depth.getHorizontalFieldOfView(), s.depth.getVerticalFieldOfView(), w, h);
  }
  f.timestamp = static_cast<double>(depth.getTimestamp()) * 1e-6;
  if (depth.getData() == nullptr || depth.getStrideInBytes() < static_cast<int>(w * sizeof(openni::DepthPixel)) ||
      static_cast<std::size_t>(depth.getDataSize()) < static_cast<std::size_t>(depth.getStrideInBytes()) * h) {
    throw BadFrame(uri_ + ": a depth frame of " + std::to_string(depth.getDataSize()) + " bytes for " +
                   std::to_string(w) + "x" + std::to_string(h) + " pixels (a short read)");
  }
  oni::fill_depth({static_cast<const std::uint8_t*>(depth.getData()), w, h, depth.getStrideInBytes()}, scale, f);
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
    const int cw = colour.getWidth(), ch = colour.getHeight();
    if (colour.getData() == nullptr || colour.getStrideInBytes() < 3 * cw ||
        static_cast<std::size_t>(colour.getDataSize()) < static_cast<std::size_t>(colour.getStrideInBytes()) * ch) {
      throw BadFrame(uri_ + ": a colour frame of " + std::to_string(colour.getDataSize()) + " bytes for " +
                     std::to_string(cw) + "x" + std::to_string(ch) + " pixels (a short read)");
    }
    oni::fill_colour({static_cast<const std::uint8_t*>(colour.getData()), cw, ch, colour.getStrideInBytes()}, f);
  }
  return f;
}

}  // namespace ofv
