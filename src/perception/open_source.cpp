// The source a user names, recognised by its form: URI scheme, file
// extension, or what the folder holds.
#include "ofv/sources/open_source.h"

#include "ofv/sources/openni2_source.h"
#include "ofv/sources/pcd_sequence.h"
#include "ofv/sources/tum_sequence.h"

#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace ofv {

std::unique_ptr<FrameSource> open_source(const std::string& source, float playback_speed, bool source_poses) {
  OpenNi2Options oni;
  oni.playback_speed = playback_speed;
  const std::string scheme = "openni2://";
  if (source.rfind(scheme, 0) == 0) {
    const std::string uri = source.substr(scheme.size());
    return std::make_unique<OpenNi2Source>(uri, oni);  // empty: the first device
  }
  if (source.size() > 4 && source.compare(source.size() - 4, 4, ".oni") == 0) {
    if (!fs::is_regular_file(source)) {
      throw std::invalid_argument(source + ": no such .oni file");
    }
    return std::make_unique<OpenNi2Source>(source, oni);
  }
  if (fs::is_directory(source)) {
    if (fs::exists(fs::path(source) / "depth.txt")) {
      TumSequenceOptions tum;
      tum.require_poses = source_poses;
      return std::make_unique<TumSequenceSource>(source, tum);
    }
    for (const auto& entry : fs::directory_iterator(source)) {
      if (entry.path().extension() == ".pcd") {
        return std::make_unique<PcdSequenceSource>(source);
      }
    }
  }
  throw std::invalid_argument(source +
                              ": not a TUM RGB-D directory, a PCD sequence, a .oni file or an "
                              "openni2:// URI");
}

}  // namespace ofv
