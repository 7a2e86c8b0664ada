// libFuzzer target: the .oni structure check (ofv::check_oni_file) that
// stands between a recording and its playback, and the playback. Invalid input must throw
// std::invalid_argument; anything else is a finding.
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ofv::fuzz::oni(data, size);
  return 0;
}
