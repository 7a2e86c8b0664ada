// The OpenNI2 record format (file format 1.0.1.0) as OniWriter writes it and
// check_oni_file() checks it; private to the perception library.
//   file header (24 bytes): "NI10", version {u8 1, u8 0, u16 1, u32 0},
//                           u64 max timestamp, u32 max node id
//   record header (28 bytes): u32 magic "NIR\0", u32 type, u32 node id,
//                           u32 fields size (header included), u32 payload size,
//                           u64 undo position; then fields, then payload
#pragma once

#include <cstddef>
#include <cstdint>

namespace ofv::oni {

enum RecordType : std::uint32_t {
  kIntProperty = 0x03,
  kRealProperty = 0x04,
  kStringProperty = 0x05,
  kGeneralProperty = 0x06,
  kNodeRemoved = 0x07,
  kNodeDataBegin = 0x08,
  kNodeStateReady = 0x09,
  kNewData = 0x0A,
  kEnd = 0x0B,
  kNodeAdded = 0x0D,
  kSeekTable = 0x0E,
};
constexpr std::uint32_t kRecordMagic = 0x0052494E;  // "NIR\0"
constexpr std::uint32_t kNodeTypeDepth = 2;
constexpr std::uint32_t kNodeTypeImage = 3;
constexpr std::uint32_t kNodeTypeIr = 4;
constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
  return static_cast<std::uint8_t>(a) | (static_cast<std::uint32_t>(static_cast<std::uint8_t>(b)) << 8) |
         (static_cast<std::uint32_t>(static_cast<std::uint8_t>(c)) << 16) |
         (static_cast<std::uint32_t>(static_cast<std::uint8_t>(d)) << 24);
}
constexpr std::uint32_t kCodecUncompressed = fourcc('N', 'O', 'N', 'E');
// The compressed ones (OpenNI2's XnCodecIDs.h; byte formats in oni_codecs.h).
constexpr std::uint32_t kCodec16z = fourcc('1', '6', 'z', 'P');
constexpr std::uint32_t kCodec16zTables = fourcc('1', '6', 'z', 'T');
constexpr std::uint32_t kCodec8z = fourcc('I', 'm', '8', 'z');
constexpr std::uint32_t kCodecJpeg = fourcc('J', 'P', 'E', 'G');
constexpr std::size_t kFileHeaderBytes = 24;
constexpr std::size_t kRecordHeaderBytes = 28;
constexpr std::size_t kMaxNameBytes = 80;  // XN_MAX_NAME_LENGTH, the terminating NUL included
/// OpenNI2's player reads a record into a buffer of 1600 x 1200 x 3 bytes past its header.
constexpr std::uint64_t kMaxPayloadBytes = 1600 * 1200 * 3;

}  // namespace ofv::oni
