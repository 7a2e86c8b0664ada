// check_oni_file(): the structure of a .oni file, walked record by record
// (OpenNI2's player trusts sizes, node ids and offsets, and crashes on a single
// changed byte), and every compressed frame decoded (oni_codecs.h): OpenNI2's
// decoders trust their payloads too. The same walk indexes the file's nodes
// and frames for OpenNi2Source's playback (oni_index.h).
#include "ofv/sources/openni2_source.h"

#include "oni_codecs.h"
#include "oni_format.h"
#include "oni_index.h"

#include <OniCEnums.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <vector>

namespace ofv {

namespace {

using namespace oni;

/// What the records said so far about one node.
struct NodeState {
  bool added = false;
  bool ready = false;  // NODE_STATE_READY: the player reads on until every added node is ready
  bool begun = false;
  std::uint32_t codec = 0;
  std::uint32_t frames = 0;      // as NODE_ADDED claims
  std::uint64_t frames_at = 0;   // offset of that claim
  std::uint64_t seek_table = 0;  // as NODE_ADDED claims
  std::uint64_t seek_table_at = 0;
  std::uint32_t seen = 0;        // NEW_DATA records
  std::uint64_t last_data = 0;
  std::uint64_t last_time = 0;
  std::uint64_t width = 0, height = 0, bytes_per_pixel = 0, required = 0;
  std::uint64_t crop_width = 0, crop_height = 0;  // 0: no cropping
  std::uint64_t crop_x = 0, crop_y = 0;
  std::uint64_t pixel_format = 0;
  std::set<std::uint64_t> data;  // NEW_DATA offsets
  std::set<std::string> properties;
  std::uint64_t table_found = 0;
  std::uint64_t order = 0;  // when it was added: the index lists nodes in that order
  NodeIndex index;
};

/// Reads the fields of one record, failing at the offset of the field that does not fit.
class Fields {
 public:
  Fields(std::vector<std::uint8_t> bytes, std::uint64_t offset,
         const std::function<void(std::uint64_t, const std::string&)>& fail)
      : bytes_(std::move(bytes)), offset_(offset), fail_(fail) {}

  template <typename T>
  T get(const char* field) {
    if (pos_ + sizeof(T) > bytes_.size()) fail_(here(), std::string("record ends inside ") + field);
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  std::string name() {
    const std::uint64_t at = here();
    const auto n = get<std::uint32_t>("a name's length");
    if (n == 0 || n > kMaxNameBytes || pos_ + n > bytes_.size() || bytes_[pos_ + n - 1] != 0) {
      fail_(at, "name length " + std::to_string(n) + " (1 to 80, NUL-terminated, inside the record)");
    }
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_));
    if (s.size() + 1 != n || s.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_") !=
                                 std::string::npos) {
      fail_(at + 4, "name is not an identifier of " + std::to_string(n - 1) + " letters, digits or _");
    }
    pos_ += n;
    return s;
  }
  const std::uint8_t* skip(std::uint64_t n, const char* field) {
    if (pos_ + n > bytes_.size()) fail_(here(), std::string("record ends inside ") + field);
    const std::uint8_t* p = bytes_.data() + pos_;
    pos_ += n;
    return p;
  }
  void end() {
    if (pos_ != bytes_.size()) fail_(offset_ + 12, "fields size " + std::to_string(bytes_.size() + kRecordHeaderBytes) +
                                                  ", the fields take " + std::to_string(pos_ + kRecordHeaderBytes));
  }
  [[nodiscard]] std::uint64_t here() const { return offset_ + kRecordHeaderBytes + pos_; }

 private:
  std::vector<std::uint8_t> bytes_;
  std::uint64_t offset_;
  std::size_t pos_ = 0;
  const std::function<void(std::uint64_t, const std::string&)>& fail_;
};

std::uint64_t bytes_per_pixel(std::uint64_t format) {
  switch (format) {
    case ONI_PIXEL_FORMAT_DEPTH_1_MM:
    case ONI_PIXEL_FORMAT_DEPTH_100_UM:
    case ONI_PIXEL_FORMAT_SHIFT_9_2:
    case ONI_PIXEL_FORMAT_SHIFT_9_3:
    case ONI_PIXEL_FORMAT_GRAY16:
    case ONI_PIXEL_FORMAT_YUV422:
    case ONI_PIXEL_FORMAT_YUYV:
      return 2;
    case ONI_PIXEL_FORMAT_RGB888:
      return 3;
    case ONI_PIXEL_FORMAT_GRAY8:
      return 1;
    default:
      return 0;
  }
}

}  // namespace

std::unique_ptr<std::istream> oni::open_oni_file(const std::string& path, std::uint64_t& size) {
  auto in = std::make_unique<std::ifstream>(path, std::ios::binary);
  std::error_code ec;
  size = std::filesystem::file_size(path, ec);
  if (!*in || ec) throw std::invalid_argument(path + ": cannot read the .oni file");
  return in;
}

void check_oni_file(const std::string& path) {
  std::uint64_t size = 0;
  const std::unique_ptr<std::istream> in = oni::open_oni_file(path, size);  // sets size first
  check_oni_file(*in, size, path);
}

void check_oni_file(std::istream& in, std::uint64_t size, const std::string& path) {
  (void)oni::index_oni_file(in, size, path);
}

std::vector<oni::NodeIndex> oni::index_oni_file(std::istream& in, std::uint64_t size, const std::string& path) {
  const std::function<void(std::uint64_t, const std::string&)> fail = [&](std::uint64_t offset,
                                                                           const std::string& what) {
    throw std::invalid_argument(path + ": offset " + std::to_string(offset) + ": " + what);
  };
  const auto read = [&](std::uint64_t offset, std::uint64_t n) {
    std::vector<std::uint8_t> bytes(n);
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(n));
    if (!in) fail(offset, "cannot read " + std::to_string(n) + " bytes");
    return bytes;
  };

  if (size < kFileHeaderBytes) fail(0, "shorter than the 24-byte file header");
  // Fields count offsets after a record header: these start at 0 (unsigned wrap-around).
  Fields header(read(0, kFileHeaderBytes), 0 - kRecordHeaderBytes, fail);
  if (header.get<std::uint32_t>("magic") != fourcc('N', 'I', '1', '0')) fail(0, "not a .oni file (magic is not NI10)");
  const auto major = header.get<std::uint8_t>("version"), minor = header.get<std::uint8_t>("version");
  const auto maintenance = header.get<std::uint16_t>("version");
  const auto build = header.get<std::uint32_t>("version");
  if (major != 1 || minor != 0 || maintenance != 1 || build != 0) {
    fail(4, "file format version " + std::to_string(major) + "." + std::to_string(minor) + "." +
                std::to_string(maintenance) + "." + std::to_string(build) + ", expected 1.0.1.0");
  }
  (void)header.get<std::uint64_t>("max timestamp");
  const auto max_node = header.get<std::uint32_t>("max node id");
  if (max_node > 16) fail(20, "max node id " + std::to_string(max_node) + ", more than 16");
  std::vector<NodeState> nodes(max_node + 1);
  std::set<std::uint64_t> records;
  std::vector<std::uint8_t> decoded;  // a compressed frame, decoded: one at a time
  std::uint64_t added = 0;

  std::uint64_t at = kFileHeaderBytes;
  for (bool end = false; !end;) {
    if (at + kRecordHeaderBytes > size) fail(at, "the file ends before its END record");
    Fields h(read(at, kRecordHeaderBytes), at - kRecordHeaderBytes, fail);
    if (h.get<std::uint32_t>("magic") != kRecordMagic) fail(at, "record magic is not NIR");
    const auto type = h.get<std::uint32_t>("type");
    const auto id = h.get<std::uint32_t>("node id");
    const auto fields_size = h.get<std::uint32_t>("fields size");
    const auto payload = h.get<std::uint32_t>("payload size");
    const auto undo = h.get<std::uint64_t>("undo position");
    const std::set<std::uint32_t> known{kIntProperty,   kRealProperty, kStringProperty, kGeneralProperty,
                                        kNodeRemoved,   kNodeDataBegin, kNodeStateReady, kNewData,
                                        kEnd,           kNodeAdded,     kSeekTable};
    if (known.count(type) == 0) fail(at + 4, "record type " + std::to_string(type));
    if (id > max_node) fail(at + 8, "node id " + std::to_string(id) + ", the header's max is " + std::to_string(max_node));
    if (fields_size < kRecordHeaderBytes || fields_size > kRecordHeaderBytes + 65536) {
      fail(at + 12, "fields size " + std::to_string(fields_size));
    }
    if ((payload != 0 && type != kNewData && type != kSeekTable) || payload > kMaxPayloadBytes) {
      fail(at + 16, "payload size " + std::to_string(payload) + " for record type " + std::to_string(type));
    }
    if (at + fields_size + payload > size) fail(at + 12, "the record runs past the end of the file");
    if (undo != 0 && records.count(undo) == 0) fail(at + 20, "undo position " + std::to_string(undo) + " is no earlier record");
    Fields f(read(at + kRecordHeaderBytes, fields_size - kRecordHeaderBytes), at, fail);
    NodeState& n = nodes[id];
    if (type != kNodeAdded && type != kEnd && !n.added) fail(at + 8, "node " + std::to_string(id) + " was not added");
    switch (type) {
      case kNodeAdded: {
        if (n.added) fail(at + 8, "node " + std::to_string(id) + " added twice");
        (void)f.name();
        const std::uint64_t type_at = f.here();
        const auto node_type = f.get<std::uint32_t>("node type");
        if (node_type != kNodeTypeDepth && node_type != kNodeTypeImage && node_type != kNodeTypeIr) {
          fail(type_at, "node type " + std::to_string(node_type));
        }
        n.index.type = node_type;
        const std::uint64_t codec_at = f.here();
        n.codec = f.get<std::uint32_t>("codec");
        if (n.codec != kCodecUncompressed && n.codec != kCodec16zTables && n.codec != kCodec16z && n.codec != kCodec8z &&
            n.codec != kCodecJpeg) {
          fail(codec_at, "codec " + std::to_string(n.codec));
        }
        n.frames_at = f.here();
        n.frames = f.get<std::uint32_t>("frame count");
        (void)f.get<std::uint64_t>("min timestamp");
        (void)f.get<std::uint64_t>("max timestamp");
        n.seek_table_at = f.here();
        n.seek_table = f.get<std::uint64_t>("seek table position");
        f.end();
        n.index.codec = n.codec;
        n.added = true;
        n.order = added++;
        break;
      }
      case kIntProperty:
      case kRealProperty:
      case kStringProperty:
      case kGeneralProperty: {
        const std::string name = f.name();
        n.properties.insert(name);
        const std::uint64_t size_at = f.here();
        const auto bytes = f.get<std::uint32_t>("property size");
        if ((type == kIntProperty || type == kRealProperty) && bytes != 8) {
          fail(size_at, "property " + name + ": size " + std::to_string(bytes) + ", expected 8");
        }
        const std::uint64_t value_at = f.here();
        const std::uint8_t* value = f.skip(bytes, "the property value");
        f.end();
        const auto u32 = [&](int k) {
          std::uint32_t v;
          std::memcpy(&v, value + 4 * k, 4);
          return v;
        };
        const auto bad = [&](const std::string& why) { fail(value_at, "property " + name + ": " + why); };
        if (type == kStringProperty && (bytes == 0 || value[bytes - 1] != 0)) bad("not a NUL-terminated string");
        if (type == kRealProperty) {
          double v;
          std::memcpy(&v, value, 8);
          if (!std::isfinite(v)) bad("not finite");
        }
        if (type == kIntProperty) {
          std::uint64_t v;
          std::memcpy(&v, value, 8);
          if (name == "oniPixelFormat" && (n.bytes_per_pixel = bytes_per_pixel(v)) == 0) bad("pixel format " + std::to_string(v));
          if (name == "oniPixelFormat") n.pixel_format = v;
          if (name == "oniRequiredFrameSize" && (v == 0 || v > kMaxPayloadBytes)) bad(std::to_string(v) + " bytes");
          if (name == "oniRequiredFrameSize") n.required = v;
        }
        if (type == kGeneralProperty && name == "xnMapOutputMode") {
          if (bytes != 12) bad("size " + std::to_string(bytes) + ", expected 12");
          n.width = u32(0);
          n.height = u32(1);
          if (n.width == 0 || n.height == 0 || n.width > 4096 || n.height > 4096 || u32(2) == 0 || u32(2) > 1000) {
            bad(std::to_string(n.width) + "x" + std::to_string(n.height) + " at " + std::to_string(u32(2)) + " fps");
          }
        }
        if (type == kGeneralProperty && name == "xnCropping") {
          if (bytes != 12) bad("size " + std::to_string(bytes) + ", expected 12");
          std::uint16_t c[4];
          std::memcpy(c, value + 4, sizeof c);
          n.crop_width = u32(0) != 0 ? c[2] : 0;
          n.crop_height = u32(0) != 0 ? c[3] : 0;
          n.crop_x = u32(0) != 0 ? c[0] : 0;
          n.crop_y = u32(0) != 0 ? c[1] : 0;
          if (u32(0) > 1 || (u32(0) == 1 && (c[2] == 0 || c[3] == 0 || std::uint64_t{c[0]} + c[2] > n.width ||
                                             std::uint64_t{c[1]} + c[3] > n.height))) {
            bad("enabled " + std::to_string(u32(0)) + ", window outside the image");
          }
        }
        if (type == kGeneralProperty && name == "xnFOV") {
          double fov[2];
          if (bytes != 16) bad("size " + std::to_string(bytes) + ", expected 16");
          std::memcpy(fov, value, sizeof fov);
          if (!(fov[0] > 0.0 && fov[0] < 3.14) || !(fov[1] > 0.0 && fov[1] < 3.14)) bad("not in (0, pi)");
          n.index.hfov = fov[0];
          n.index.vfov = fov[1];
        }
        break;
      }
      case kNodeRemoved:
        f.end();
        n = NodeState{};
        break;
      case kNodeStateReady:
        f.end();
        if (n.ready) fail(at + 8, "node " + std::to_string(id) + " ready twice");
        n.ready = true;
        break;
      case kNodeDataBegin:
        if (!n.ready || n.begun) fail(at + 8, "data of node " + std::to_string(id) + " begins before it is ready, or twice");
        (void)f.get<std::uint32_t>("frame count");
        (void)f.get<std::uint64_t>("max timestamp");
        f.end();
        n.begun = true;
        break;
      case kNewData: {
        if (!n.begun) fail(at + 8, "data of node " + std::to_string(id) + " before its DATA_BEGIN");
        for (std::size_t other = 0; other < nodes.size(); ++other) {
          if (nodes[other].added && !nodes[other].ready) fail(at, "data before node " + std::to_string(other) + " is ready");
        }
        const auto time = f.get<std::uint64_t>("timestamp");
        const std::uint64_t frame_at = f.here();
        const auto frame = f.get<std::uint32_t>("frame number");
        f.end();
        if (frame != n.seen + 1) fail(frame_at, "frame number " + std::to_string(frame) + ", expected " + std::to_string(n.seen + 1));
        if (time < n.last_time) fail(at + kRecordHeaderBytes, "timestamp goes backwards");
        if (undo != n.last_data) fail(at + 20, "undo position " + std::to_string(undo) + " is not the node's previous frame");
        for (const char* needed : {"oniRequiredFrameSize", "xnIsGenerating", "xnMapOutputMode", "oniPixelFormat"}) {
          if (n.properties.count(needed) == 0) {
            fail(at, "frame of node " + std::to_string(id) + " before its property " + needed);
          }
        }
        const FrameShape shape{n.crop_width != 0 ? n.crop_width : n.width, n.crop_width != 0 ? n.crop_height : n.height,
                               n.bytes_per_pixel};
        const std::uint64_t expected = shape.bytes();
        if (n.codec == kCodecUncompressed && (payload != expected || n.required != expected)) {
          fail(at + 16, "payload size " + std::to_string(payload) + ", the node's mode and pixel format need " + std::to_string(expected));
        }
        if (payload == 0) fail(at + 16, "empty frame");
        if (n.codec != kCodecUncompressed) {
          if (n.required != expected) {
            fail(at, "frame of node " + std::to_string(id) + ": oniRequiredFrameSize " + std::to_string(n.required) +
                         ", the node's mode and pixel format need " + std::to_string(expected));
          }
          // OpenNI2's decoders trust the payload: it must decode, bounded, to exactly that frame.
          const std::string why = decode_frame(n.codec, read(at + fields_size, payload).data(), payload, shape, decoded);
          if (!why.empty()) fail(at + fields_size, why);
        }
        n.index.frames.push_back({at + fields_size, payload, time, shape.width, shape.height, n.crop_x, n.crop_y, n.width,
                                  n.height, n.pixel_format, n.bytes_per_pixel});
        n.last_data = at;
        n.last_time = time;
        n.data.insert(at);
        ++n.seen;
        break;
      }
      case kSeekTable: {
        f.end();
        if (payload != (std::uint64_t{n.frames} + 1) * 20) {
          fail(at + 16, "seek table of " + std::to_string(payload) + " bytes for " + std::to_string(n.frames) + " frames");
        }
        const std::vector<std::uint8_t> table = read(at + fields_size, payload);
        for (std::uint64_t k = 0; k < payload; k += 20) {
          std::uint64_t position;
          std::memcpy(&position, table.data() + k + 12, 8);
          if (position != 0 && n.data.count(position) == 0) {
            fail(at + fields_size + k + 12, "seek table entry " + std::to_string(position) + " is no frame of the node");
          }
        }
        n.table_found = at;
        break;
      }
      case kEnd:
        f.end();
        end = true;
        break;
      default:
        break;
    }
    records.insert(at);
    at += std::uint64_t{fields_size} + payload;
  }
  for (std::size_t id = 0; id < nodes.size(); ++id) {
    const NodeState& n = nodes[id];
    if (n.added && n.frames != n.seen) {
      fail(n.frames_at, "node " + std::to_string(id) + " claims " + std::to_string(n.frames) + " frames, the file has " +
                            std::to_string(n.seen));
    }
    if (n.added && n.seek_table != 0 && n.seek_table != n.table_found) {
      fail(n.seek_table_at, "seek table position " + std::to_string(n.seek_table) + " is not the node's seek table");
    }
  }
  std::vector<NodeState*> added_nodes;
  for (NodeState& n : nodes) {
    if (n.added) added_nodes.push_back(&n);
  }
  std::sort(added_nodes.begin(), added_nodes.end(), [](const NodeState* a, const NodeState* b) { return a->order < b->order; });
  std::vector<NodeIndex> index;
  for (NodeState* n : added_nodes) index.push_back(std::move(n->index));
  return index;
}

}  // namespace ofv
