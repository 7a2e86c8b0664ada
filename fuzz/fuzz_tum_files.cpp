// libFuzzer target: the text files of recorded sequences, each parser on the
// same input: TUM pose files (groundtruth.txt, poses.txt, FILE.oni.poses.txt),
// intrinsics.txt and the TUM image lists (rgb.txt, depth.txt); a parsed pose
// list is then interpolated as a source does. These parsers document
// std::runtime_error for a bad line; anything else is a finding.
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ofv::fuzz::tum_files(data, size);
  return 0;
}
