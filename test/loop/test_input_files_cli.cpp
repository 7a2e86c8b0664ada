// End to end: hostile scenario files, meshes, poses and recordings make the
// `ofv` commands that read them exit 2 with one line naming the file, the
// field and the value, never crash or hang them (issue #13, item 1).
#include "cli_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace ofv {
namespace {

fs::path scratch(const std::string& name) { return fs::path(test::scratch_dir()) / name; }

fs::path write(const std::string& name, const std::string& bytes) {
  const fs::path p = scratch(name);
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
  return p;
}

/// Expects exit 2 and one line on stderr naming every word of `mentions`.
void expect_bad_input(const std::string& args, const std::vector<std::string>& mentions) {
  const CommandRun r = run(args);
  EXPECT_EQ(r.code, 2) << args << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  for (const std::string& m : mentions) {
    EXPECT_NE(r.err.find(m), std::string::npos) << args << ": " << r.err;
  }
}

std::string render(const fs::path& scenario) {
  return "render " + scenario.string() + " --out " + scratch("render").string();
}

TEST(InputFilesCli, ScenarioYamlRepeatedKeysDepthAndBoundsAreExitTwo) {
  const std::string object = "object: {shape: box}\n";
  struct Case {
    std::string name, yaml;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases{
      {"dup_top.yaml", "duration: 1\n" + object + "duration: 2\n", {"dup_top.yaml:3", "duplicate key 'duration'"}},
      {"dup_inner.yaml", "object: {shape: box, shape: sphere}\n", {"dup_inner.yaml:1", "duplicate key 'shape'"}},
      {"deep.yaml", object + "description: " + std::string(40, '[') + std::string(40, ']') + "\n",
       {"deep.yaml", "nested deeper than"}},
      {"very_deep.yaml", object + "description: " + std::string(100000, '[') + std::string(100000, ']') + "\n",
       {"very_deep.yaml"}},
      {"cloth.yaml", "object: {shape: cloth, grid: [100000, 100000]}\n", {"cloth.yaml", "object.grid[0]", "100000"}},
      {"overflow.yaml", "object: {shape: cloth, grid: [99999999999, 2]}\n", {"overflow.yaml", "object.grid[0]"}},
      {"duration.yaml", object + "duration: 1e12\n", {"duration.yaml", "duration", "1e12"}},
      {"rate.yaml", object + "rate: 1e9\n", {"rate.yaml", "rate", "1e9"}},
      {"width.yaml", object + "sensor: {width: 100000}\n", {"width.yaml", "sensor.width", "100000"}},
      {"size.yaml", "object: {shape: box, size: [1e30, 1, 1]}\n", {"size.yaml", "object.size[0]", "1e30"}},
      {"speed.yaml", object + "controller: {max_linear_speed: 1e300}\n", {"speed.yaml", "controller.max_linear_speed"}},
      {"t.yaml", "object: {shape: box, waypoints: [{t: 0}, {t: 1e300}]}\n", {"t.yaml", "object.waypoints[1].t"}},
  };
  for (const Case& c : cases) {
    expect_bad_input(render(write(c.name, c.yaml)), c.mentions);
  }
}

/// A binary little-endian PLY: the header (counts as given) and `vertices` x 3 floats, one face.
std::string binary_ply(std::uint64_t claimed_vertices, const std::vector<float>& xyz) {
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                    std::to_string(claimed_vertices) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n";
  ply.append(reinterpret_cast<const char*>(xyz.data()), xyz.size() * sizeof(float));
  const unsigned char n = 3;
  const std::int32_t face[3] = {0, 1, 2};
  ply.append(reinterpret_cast<const char*>(&n), 1);
  ply.append(reinterpret_cast<const char*>(face), sizeof face);
  return ply;
}

TEST(InputFilesCli, BrokenMeshesAreExitTwoNamingTheFile) {
  const std::string ascii_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::vector<float> triangle{0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0};
  const std::string good = binary_ply(3, triangle);
  struct Case {
    std::string name, bytes;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases{
      {"nan.ply", ascii_head + "0 0 0\nnan 0 0\n0 0.1 0\n3 0 1 2\n", {"nan.ply", "vertex 1"}},
      {"inf.ply", binary_ply(3, {0, 0, 0, 1e38f, 0, 0, 0, 0.1f, 0}), {"inf.ply", "vertex 1"}},
      {"truncated.ply", good.substr(0, good.size() - 20), {"truncated.ply", "bytes"}},
      {"claims_1e8.ply", binary_ply(100000000, triangle), {"claims_1e8.ply", "100000000"}},
      {"claims_1e6.ply", binary_ply(1000000, triangle), {"claims_1e6.ply", "bytes"}},
      {"garbage.ply", "ply\nformat binary_little_endian 1.0\nelement vertex x\nend_header\n",
       {"garbage.ply", "count"}},
      {"no_header_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", {"no_header_end.ply"}},
      {"nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", {"nan.obj"}},
  };
  const fs::path ok = write("good.ply", good);
  const fs::path scenario = write("mesh_ok.yaml", "object: {shape: mesh, file: " + ok.string() + "}\n");
  ASSERT_EQ(run(render(scenario)).code, 0);
  for (const Case& c : cases) {
    const fs::path mesh = write(c.name, c.bytes);
    const fs::path yaml = write(c.name + ".yaml", "object: {shape: mesh, file: " + mesh.string() + "}\n");
    expect_bad_input(render(yaml), c.mentions);
  }
  // A mesh of 50 m scaled by 1000: beyond 10 km.
  const fs::path far = write("far.ply", binary_ply(3, {0, 0, 0, 50, 0, 0, 0, 50, 0}));
  expect_bad_input(render(write("scaled.yaml", "object: {shape: mesh, file: " + far.string() + ", scale: 1000}\n")),
                   {"far.ply", "vertex 1"});
}

TEST(InputFilesCli, NonFinitePosesAreExitTwo) {
  for (const char* pose : {"nan,0,0,0,0,0", "0,0,0,inf,0,0", "0,0,1e300,0,0,0", "0,0,0,0,-nan,0"}) {
    expect_bad_input(std::string("render dvd-static --pose ") + pose + " --out " + scratch("render").string(), {"--pose"});
  }
  expect_bad_input("render dvd-static --time inf --out " + scratch("render").string(), {"--time"});
}

TEST(InputFilesCli, ABrokenPcdFrameMidRunIsExitTwo) {
  const fs::path dir = scratch("run_pcd");
  ASSERT_EQ(run("record dvd-one-hand --format pcd --out " + dir.string() + " --until 0.2").code, 0);
  write("run_pcd/000003.pcd", "");
  const CommandRun r = run("run --robot camera --source " + dir.string() + " --dry-run");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("000003.pcd"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("\"frame\": 2"), std::string::npos) << "frames before the broken one run";
}

}  // namespace
}  // namespace ofv
