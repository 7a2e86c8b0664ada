// libFuzzer target: the scene JSON of `ofv estimate` (ofv::scene_from_text,
// what read_scene() parses). Invalid input must throw std::invalid_argument;
// any other exception, crash, leak or hang is a finding.
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ofv::fuzz::scene_json(data, size);
  return 0;
}
