#include "openni2_player.h"

#include <OpenNI.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <thread>

namespace ofv::test {

namespace {

template <typename T>
std::vector<T> pixels(const openni::VideoFrameRef& f, int bytes_per_pixel) {
  std::vector<T> out(static_cast<std::size_t>(f.getWidth()) * static_cast<std::size_t>(f.getHeight()) *
                     static_cast<std::size_t>(bytes_per_pixel) / sizeof(T));
  const auto* data = static_cast<const std::uint8_t*>(f.getData());
  const std::size_t row = static_cast<std::size_t>(f.getWidth()) * static_cast<std::size_t>(bytes_per_pixel);
  for (int v = 0; v < f.getHeight(); ++v) {
    std::memcpy(reinterpret_cast<std::uint8_t*>(out.data()) + v * row,
                data + static_cast<std::size_t>(v) * static_cast<std::size_t>(f.getStrideInBytes()), row);
  }
  return out;
}

bool read(openni::VideoStream& stream, openni::VideoFrameRef& frame) {
  openni::VideoStream* streams[] = {&stream};
  int ready = -1;
  return openni::OpenNI::waitForAnyStream(streams, 1, &ready, 3000) == openni::STATUS_OK &&
         stream.readFrame(&frame) == openni::STATUS_OK && frame.isValid();
}

}  // namespace

OpenNi2Playback play_with_openni2(const std::string& path) {
  OpenNi2Playback out;
  EXPECT_EQ(openni::OpenNI::initialize(), openni::STATUS_OK) << openni::OpenNI::getExtendedError();
  openni::Device device;
  openni::VideoStream depth, colour;
  if (device.open(path.c_str()) != openni::STATUS_OK || depth.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    ADD_FAILURE() << path << ": OpenNI2 cannot play it: " << openni::OpenNI::getExtendedError();
    return out;
  }
  const bool has_colour = device.hasSensor(openni::SENSOR_COLOR) &&
                          colour.create(device, openni::SENSOR_COLOR) == openni::STATUS_OK;
  device.getPlaybackControl()->setRepeatEnabled(false);
  device.getPlaybackControl()->setSpeed(-1.0f);
  const int frames = device.getPlaybackControl()->getNumberOfFrames(depth);
  out.hfov = depth.getHorizontalFieldOfView();
  out.vfov = depth.getVerticalFieldOfView();
  depth.start();
  if (has_colour) colour.start();
  for (int k = 0; k < frames; ++k) {
    openni::VideoFrameRef f;
    if (!read(depth, f)) {
      ADD_FAILURE() << path << ": OpenNI2 gives no depth frame " << k;
      break;
    }
    out.width = f.getWidth();
    out.height = f.getHeight();
    out.time_us.push_back(f.getTimestamp());
    out.depth.push_back(pixels<std::uint16_t>(f, 2));
    if (has_colour) {
      if (!read(colour, f)) {
        ADD_FAILURE() << path << ": OpenNI2 gives no colour frame " << k;
        break;
      }
      out.rgb.push_back(pixels<std::uint8_t>(f, 3));
    }
  }
  depth.stop();
  colour.stop();
  // The player thread is still at work for a while after stop(): destroying
  // or closing at once crashes it (openni2_source.cpp).
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  depth.destroy();
  colour.destroy();
  device.close();
  return out;
}

}  // namespace ofv::test
