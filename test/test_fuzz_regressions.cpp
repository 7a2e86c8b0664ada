// Replays through the fuzz targets' functions (fuzz/fuzz_targets.h) the
// seeds in fuzz/corpus/<target>/ and every input a fuzzer once found in
// test/data/fuzz-regressions/<target>/: the normal build checks them without
// clang, and the sanitizer build of CI with ASan + UBSan.
#include "fuzz_targets.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using Target = void (*)(const std::uint8_t*, std::size_t);

// Every file of the target's seeds and regressions through `run`; returns how many.
int replay(const std::string& target, Target run) {
  int count = 0;
  for (const fs::path& dir : {fs::path(OFV_SOURCE_DIR) / "fuzz" / "corpus" / target,
                             fs::path(OFV_SOURCE_DIR) / "test" / "data" / "fuzz-regressions" / target}) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir)) {
      std::ifstream in(entry.path(), std::ios::binary);
      const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      SCOPED_TRACE(entry.path().string());
      EXPECT_NO_THROW(run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
      ++count;
    }
  }
  return count;
}

}  // namespace

TEST(FuzzRegressions, SceneJsonInputsAreParsedOrRejected) { EXPECT_GT(replay("fuzz_scene_json", ofv::fuzz::scene_json), 0); }
TEST(FuzzRegressions, ScenarioYamlInputsAreParsedOrRejected) {
  EXPECT_GT(replay("fuzz_scenario_yaml", ofv::fuzz::scenario_yaml), 0);
}
TEST(FuzzRegressions, GridYamlInputsAreParsedOrRejected) { EXPECT_GT(replay("fuzz_grid_yaml", ofv::fuzz::grid_yaml), 0); }
TEST(FuzzRegressions, SequenceTextFilesAreParsedOrRejected) { EXPECT_GT(replay("fuzz_tum_files", ofv::fuzz::tum_files), 0); }
TEST(FuzzRegressions, PcdHeadersAreCheckedOrRejected) { EXPECT_GT(replay("fuzz_pcd_header", ofv::fuzz::pcd_header), 0); }
TEST(FuzzRegressions, OniFilesAreCheckedOrRejected) { EXPECT_GT(replay("fuzz_oni", ofv::fuzz::oni), 0); }
