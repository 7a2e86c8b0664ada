// libFuzzer target: the PCD header check (ofv::check_pcd_header) that stands
// between a PCD sequence and PCL's reader. Invalid input must throw
// std::invalid_argument; anything else is a finding.
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ofv::fuzz::pcd_header(data, size);
  return 0;
}
