// libFuzzer target: the settings grid of `ofv compare --grid` (ofv::grid_from_yaml).
// Invalid input must throw std::invalid_argument; anything else is a finding.
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ofv::fuzz::grid_yaml(data, size);
  return 0;
}
