// libFuzzer target: the scenario YAML of `ofv simulate` (ofv::sim::scenario_from_yaml),
// then the scenario's random worlds (with_seed), which use every parsed motion.
// Invalid input must throw std::invalid_argument; anything else is a finding.
// Mesh and trajectory files are looked up relative to the working directory.
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ofv::fuzz::scenario_yaml(data, size);
  return 0;
}
