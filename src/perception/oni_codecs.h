// The decoders of the compressed frames a .oni file may hold (the codecs of
// OpenNI2's OniFile player), bounded: check_oni_file() decodes every
// compressed payload with them (OpenNI2's own decoders trust the payload: an
// escape at its end, a run or a table index past the frame, a JPEG stream cut
// short), and OpenNi2Source plays recordings with them. Private to the
// perception library.
//
// The byte formats (learned from OpenNI2's Source/Drivers/OniFile/Formats/, not
// copied from it). Every 16-bit word is little-endian unless said otherwise.
//   16zP ("16z", 16-bit pixels): the first pixel as a u16, then a byte stream:
//     0x00-0xDF  two nibbles, each a difference d: pixel = previous - (d - 6);
//                a low nibble 0xD ends the byte with the high one alone, and a
//                low nibble 0xF is an escape: the pixel after the high one
//                follows as for 0xFF below
//     0xFF       escape: the next byte b has its top bit set: pixel = previous
//                - (b - 192); else pixel = b << 8 | the byte after (big-endian)
//     0xE0-0xFE  a run: 2 x (byte - 0xE0) copies of the previous pixel
//   16zT ("16z with embedded tables"): a u16 count N, N u16 values (the
//     table), then a 16zP stream of indices into the table: pixel = table[index].
//   Im8z ("8z", 8-bit pixels): the first pixel as a byte, then:
//     0x00-0xDF  two nibbles as in 16zP, but a low nibble 0xF means the next
//                byte is the next pixel itself
//     0xF0-0xFF  pixel = (byte & 0x0F) << 4 | next >> 4; that next byte's low
//                nibble then is a difference, 0xD (nothing) or 0xF (the byte
//                after is the next pixel itself)
//     0xE0-0xEF  a run: 2 x (byte - 0xE0) copies of the previous pixel
//   JPEG: one JPEG stream, SOI to EOI, decoded by libjpeg to RGB: 1 component
//     for GRAY8 frames, 3 for RGB888 ones (OpenNI2's codec factory refuses
//     JPEG for other formats). OpenNI2 reads it from memory and cannot give
//     libjpeg more: a stream cut short before EOI is refused here.
// All arithmetic on pixels (16zP, 16zT indices) or bytes (Im8z) wraps as
// OpenNI2's decoders' does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ofv::oni {

/// \brief The frame a compressed payload must decode to: the node's (cropped)
///        mode and the bytes per pixel of its pixel format.
struct FrameShape {
  std::uint64_t width = 0;
  std::uint64_t height = 0;
  std::uint64_t bytes_per_pixel = 0;
  /// \brief The frame's size in bytes.
  [[nodiscard]] std::uint64_t bytes() const { return width * height * bytes_per_pixel; }
};

/// \brief The name of a codec fourcc as the checker's messages give it ("16zT", ...).
std::string codec_name(std::uint32_t codec);

/// \brief Decodes the compressed frame payload `data` (`size` bytes) of codec
///        `codec` (16zP, 16zT, Im8z or JPEG) into `frame`, never reading past
///        the payload nor writing past `shape.bytes()` bytes.
/// \param frame resized to `shape.bytes()`; its content is unspecified when
///        decoding fails (reused from call to call, it bounds the memory: one frame)
/// \return empty when the payload decodes to exactly the frame `shape`
///         describes (JPEG: its width, height and channels), else what is wrong
///         ("16zT payload: byte 812: the run of 30 pixels ends past the frame
///         of 38400 pixels", "... decodes to 1000 bytes, the frame needs 614400")
std::string decode_frame(std::uint32_t codec, const std::uint8_t* data, std::size_t size, const FrameShape& shape,
                         std::vector<std::uint8_t>& frame);

}  // namespace ofv::oni
