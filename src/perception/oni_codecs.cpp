// Bounded decoders of the .oni codecs (formats in oni_codecs.h). Each reads
// the payload through Payload and writes the frame through Pixels, which
// refuse, naming the payload byte, a read past the payload or a write past
// the frame: OpenNI2's own decoders check neither reliably.
#include "oni_codecs.h"

#include "oni_format.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstring>
#include <utility>

namespace ofv::oni {

namespace {

/// Why a payload does not decode; caught by decode_frame().
struct Refused {
  std::string why;
};

[[noreturn]] void refuse(std::string why) { throw Refused{std::move(why)}; }

std::string byte_at(std::size_t at) { return "byte " + std::to_string(at) + ": "; }

/// The payload, read forwards.
class Payload {
 public:
  Payload(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  [[nodiscard]] bool done() const { return pos_ == size_; }
  [[nodiscard]] std::size_t at() const { return pos_; }
  /// Skips `n` bytes, all of them inside the payload.
  void skip(std::size_t n, const char* inside) {
    if (n > size_ - pos_) refuse(byte_at(pos_) + "the payload ends inside " + inside);
    pos_ += n;
  }
  std::uint8_t byte(const char* inside) {
    if (pos_ == size_) refuse(byte_at(pos_) + "the payload ends inside " + inside);
    return data_[pos_++];
  }
  std::uint16_t u16(const char* inside) {
    const std::uint8_t low = byte(inside);
    return static_cast<std::uint16_t>(low | byte(inside) << 8);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// The frame, written pixel by pixel (T: std::uint16_t or std::uint8_t).
template <typename T>
class Pixels {
 public:
  explicit Pixels(std::vector<std::uint8_t>& frame) : frame_(frame), capacity_(frame.size() / sizeof(T)) {}
  /// One pixel, decoded from the code at payload byte `at`.
  void put(T value, std::size_t at) { run(value, 1, at); }
  void run(T value, std::size_t count, std::size_t at) {
    if (count > capacity_ - n_) {
      refuse(byte_at(at) + (count == 1 ? "a pixel" : "the run of " + std::to_string(count) + " pixels ends") +
             " past the frame of " + std::to_string(capacity_) + " pixels");
    }
    for (; count > 0; --count, ++n_) std::memcpy(frame_.data() + n_ * sizeof(T), &value, sizeof(T));
  }
  /// Refuses a payload that ended before the frame did.
  void finish() const {
    if (n_ != capacity_) {
      refuse("decodes to " + std::to_string(n_ * sizeof(T)) + " bytes, the frame needs " +
             std::to_string(frame_.size()));
    }
  }

 private:
  std::vector<std::uint8_t>& frame_;
  std::size_t capacity_;
  std::size_t n_ = 0;
};

/// The 16z stream after its first value (16zP: depths; 16zT: indices into the
/// table): `pixel(value, at)` gives the pixel written for a value.
template <typename Pixel>
void decode_16z_stream(Payload& in, Pixels<std::uint16_t>& out, std::uint16_t value, const Pixel& pixel) {
  // After 0xFF or a low nibble 0xF: a difference of 7 or more, or a whole value.
  const auto escape = [&](std::size_t at) {
    const std::uint8_t b = in.byte("an escape");
    value = static_cast<std::uint16_t>((b & 0x80) != 0 ? value + 192 - b : b << 8 | in.byte("an escape"));
    out.put(pixel(value, at), at);
  };
  while (!in.done()) {
    const std::size_t at = in.at();
    const std::uint8_t b = in.byte("a code");
    if (b < 0xE0) {
      value = static_cast<std::uint16_t>(value + 6 - (b >> 4));
      out.put(pixel(value, at), at);
      const int low = b & 0x0F;
      if (low == 0x0F) {
        escape(at);
      } else if (low != 0x0D) {  // 0xD: the high nibble was the last difference
        value = static_cast<std::uint16_t>(value + 6 - low);
        out.put(pixel(value, at), at);
      }
    } else if (b == 0xFF) {
      escape(at);
    } else {
      out.run(pixel(value, at), 2 * std::size_t{b - 0xE0u}, at);
    }
  }
  out.finish();
}

void decode_16z(Payload& in, std::vector<std::uint8_t>& frame) {
  Pixels<std::uint16_t> out(frame);
  const std::uint16_t first = in.u16("the first pixel");
  out.put(first, 0);
  decode_16z_stream(in, out, first, [](std::uint16_t value, std::size_t) { return value; });
}

void decode_16z_tables(Payload& in, const std::uint8_t* data, std::vector<std::uint8_t>& frame) {
  Pixels<std::uint16_t> out(frame);
  const std::uint16_t count = in.u16("the table's size");
  const std::size_t table_at = in.at();
  in.skip(2 * std::size_t{count}, ("the table of " + std::to_string(count) + " values").c_str());
  // OpenNI2 looks indices up unchecked: one past the table reads the stream after it.
  const auto pixel = [&](std::uint16_t index, std::size_t at) {
    if (index >= count) {
      refuse(byte_at(at) + "index " + std::to_string(index) + " outside the table of " + std::to_string(count) +
             " values");
    }
    return static_cast<std::uint16_t>(data[table_at + 2 * index] | data[table_at + 2 * index + 1] << 8);
  };
  const std::size_t first_at = in.at();
  const std::uint16_t first = in.u16("the first index");
  out.put(pixel(first, first_at), first_at);
  decode_16z_stream(in, out, first, pixel);
}

void decode_8z(Payload& in, std::vector<std::uint8_t>& frame) {
  Pixels<std::uint8_t> out(frame);
  std::uint8_t value = in.byte("the first pixel");
  out.put(value, 0);
  // The low nibble of a byte of two: a difference, 0xD (nothing) or 0xF (a whole pixel follows).
  const auto low_nibble = [&](int low, std::size_t at) {
    if (low == 0x0F) {
      value = in.byte("a whole pixel");
      out.put(value, at);
    } else if (low != 0x0D) {
      value = static_cast<std::uint8_t>(value + 6 - low);
      out.put(value, at);
    }
  };
  while (!in.done()) {
    const std::size_t at = in.at();
    const std::uint8_t b = in.byte("a code");
    if (b < 0xE0) {
      value = static_cast<std::uint8_t>(value + 6 - (b >> 4));
      out.put(value, at);
      low_nibble(b & 0x0F, at);
    } else if (b >= 0xF0) {  // a whole pixel over two bytes, then a low nibble
      const std::uint8_t next = in.byte("a whole pixel");
      value = static_cast<std::uint8_t>((b & 0x0F) << 4 | next >> 4);
      out.put(value, at);
      low_nibble(next & 0x0F, at);
    } else {
      out.run(value, 2 * std::size_t{b - 0xE0u}, at);
    }
  }
  out.finish();
}

/// Walks the JPEG markers up to the frame header (SOFn) and refuses a stream
/// whose frame is not `shape`, before OpenCV allocates its image; and a stream
/// that does not end with EOI: libjpeg asks OpenNI2's source for more bytes,
/// which it never gets.
void check_jpeg_header(const std::uint8_t* p, std::size_t size, const FrameShape& shape) {
  if (size < 4 || p[0] != 0xFF || p[1] != 0xD8) refuse(byte_at(0) + "no JPEG start of image");
  if (p[size - 2] != 0xFF || p[size - 1] != 0xD9) refuse(byte_at(size - 2) + "no JPEG end of image: cut short?");
  for (std::size_t at = 2;;) {
    while (at + 1 < size && p[at] == 0xFF && p[at + 1] == 0xFF) ++at;  // fill bytes
    if (at + 1 >= size || p[at] != 0xFF) refuse(byte_at(at) + "no JPEG marker where one should start");
    const std::uint8_t marker = p[at + 1];
    if (marker == 0xDA || marker == 0xD9) refuse(byte_at(at) + "the JPEG stream has no frame header before its scan");
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // markers without a segment
      at += 2;
      continue;
    }
    const std::size_t length = at + 4 <= size ? std::size_t{p[at + 2]} << 8 | p[at + 3] : 0;
    if (length < 2 || at + 2 + length > size) refuse(byte_at(at) + "a JPEG segment runs past the payload");
    const bool frame_header = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame_header) {
      if (length < 8) refuse(byte_at(at) + "a JPEG frame header of " + std::to_string(length) + " bytes");
      const std::uint64_t height = std::uint64_t{p[at + 5]} << 8 | p[at + 6];
      const std::uint64_t width = std::uint64_t{p[at + 7]} << 8 | p[at + 8];
      if (p[at + 4] != 8 || width != shape.width || height != shape.height || p[at + 9] != shape.bytes_per_pixel) {
        refuse(byte_at(at) + "a " + std::to_string(width) + "x" + std::to_string(height) + " JPEG of " +
               std::to_string(p[at + 9]) + " components of " + std::to_string(p[at + 4]) + " bits, the frame is " +
               std::to_string(shape.width) + "x" + std::to_string(shape.height) + " of " +
               std::to_string(shape.bytes_per_pixel) + " of 8 bits");
      }
      return;
    }
    at += 2 + length;
  }
}

void decode_jpeg(const std::uint8_t* data, std::size_t size, const FrameShape& shape,
                 std::vector<std::uint8_t>& frame) {
  if (shape.bytes_per_pixel != 1 && shape.bytes_per_pixel != 3) {
    refuse("OpenNI2 decodes JPEG to GRAY8 or RGB888 only, the node's pixels have " +
           std::to_string(shape.bytes_per_pixel) + " bytes");
  }
  check_jpeg_header(data, size, shape);
  cv::Mat image;
  try {
    // imdecode only reads its input.
    image = cv::imdecode(cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<std::uint8_t*>(data)),
                         cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    refuse("does not decode: " + e.err);
  }
  const auto channels = static_cast<std::uint64_t>(image.channels());
  if (image.empty() || image.depth() != CV_8U || static_cast<std::uint64_t>(image.cols) != shape.width ||
      static_cast<std::uint64_t>(image.rows) != shape.height || channels != shape.bytes_per_pixel) {
    refuse("does not decode to the frame's " + std::to_string(shape.width) + "x" + std::to_string(shape.height) +
           " pixels of " + std::to_string(shape.bytes_per_pixel) + " bytes");
  }
  // OpenCV gives BGR, OpenNI2 (libjpeg) RGB.
  for (int row = 0; row < image.rows; ++row) {
    const std::uint8_t* from = image.ptr<std::uint8_t>(row);
    std::uint8_t* to = frame.data() + static_cast<std::size_t>(row) * shape.width * channels;
    for (std::size_t k = 0; k < shape.width * channels; k += channels) {
      for (std::size_t c = 0; c < channels; ++c) to[k + c] = from[k + channels - 1 - c];
    }
  }
}

}  // namespace

std::string codec_name(std::uint32_t codec) {
  std::string name;
  for (int k = 0; k < 4; ++k) {
    const auto c = static_cast<char>(codec >> (8 * k) & 0xFF);
    if (c < ' ' || c > '~') return std::to_string(codec);
    name += c;
  }
  return name;
}

std::string decode_frame(std::uint32_t codec, const std::uint8_t* data, std::size_t size, const FrameShape& shape,
                         std::vector<std::uint8_t>& frame) {
  try {
    // OpenNI2's player decodes into a buffer of kMaxPayloadBytes.
    if (shape.bytes() == 0 || shape.bytes() > kMaxPayloadBytes) {
      refuse("a frame of " + std::to_string(shape.bytes()) + " bytes, OpenNI2's player decodes 1 to " +
             std::to_string(kMaxPayloadBytes));
    }
    if (size > kMaxPayloadBytes) {
      refuse(std::to_string(size) + " bytes, OpenNI2's player reads at most " + std::to_string(kMaxPayloadBytes));
    }
    frame.resize(shape.bytes());
    Payload in(data, size);
    switch (codec) {
      case kCodec16z:
      case kCodec16zTables:
        if (shape.bytes() % 2 != 0) refuse("the frame of " + std::to_string(shape.bytes()) + " bytes is no 16-bit pixels");
        codec == kCodec16z ? decode_16z(in, frame) : decode_16z_tables(in, data, frame);
        break;
      case kCodec8z:
        decode_8z(in, frame);
        break;
      case kCodecJpeg:
        decode_jpeg(data, size, shape, frame);
        break;
      default:
        refuse("no decoder for this codec");
    }
  } catch (const Refused& r) {
    return codec_name(codec) + " payload: " + r.why;
  }
  return {};
}

}  // namespace ofv::oni
