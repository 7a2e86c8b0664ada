// End to end through the real `ofv` binary.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cli : public testing::Test {
 protected:
  void SetUp() override {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("ofv_cli_" + std::string(info->name()) + "_" +
                                        std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `ofv ARGS` with no standard input.
  CommandResult ofv(const std::string& args) const {
    const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
    const std::string cmd = std::string("\"") + OFV_BINARY + "\" " + args + " >\"" +
                            out.string() + "\" 2>\"" + err.string() + "\" </dev/null";
    const int status = std::system(cmd.c_str());
    CommandResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }

  fs::path dir_;
};

const std::string kExample = std::string(OFV_SOURCE_DIR) + "/data/scenes/dvd-case-hand.json";

TEST_F(Cli, HelpExplainsEverySetting) {
  const CommandResult top = ofv("--help");
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_NE(top.out.find("estimate"), std::string::npos);
  const CommandResult r = ofv("estimate --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* s : {"preset", "r_seed", "r_sphere", "initial_view", "clearance", "push_radius",
                        "push_weighting", "step", "max_iterations", "warm_start", "[m]",
                        "default"}) {
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  }
}

TEST_F(Cli, EstimatesTheShippedExample) {
  const CommandResult r = ofv("estimate " + kExample);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty());
  const json j = json::parse(r.out);
  EXPECT_EQ(j["status"], "converged");
  EXPECT_GT(j["iterations"].get<int>(), 0);
  // The hand is on the left (-x): the view moves right.
  EXPECT_GT(j["tf"][0].get<double>(), j["t0"][0].get<double>());
  EXPECT_GT(j["angular_error_deg"]["tf"]["mean"].get<double>(),
            j["angular_error_deg"]["t0"]["mean"].get<double>());
}

TEST_F(Cli, SetOverridesTheFile) {
  const CommandResult r = ofv("estimate " + kExample + " --set max_iterations=0 --set step=0.01 --compact");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["status"], "not_converged");
  EXPECT_EQ(j["iterations"], 0);
  EXPECT_EQ(j["tf"], j["t0"]);

  const CommandResult path = ofv("estimate " + kExample + " --path --compact");
  const json k = json::parse(path.out);
  EXPECT_EQ(k["path"].size(), k["iterations"].get<std::size_t>() + 1);
}

TEST_F(Cli, ConformanceCaseThroughTheBinary) {
  const std::string dir = std::string(OFV_TEST_DATA_DIR) + "/conformance/";
  for (const char* name : {"edge-warm-start", "edge-authors-code-preset", "random-34"}) {
    const CommandResult r = ofv("estimate " + dir + name + ".json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json got = json::parse(r.out);
    const json expected = json::parse(slurp(dir + name + ".expected.json"));
    EXPECT_EQ(got["status"], expected["status"]) << name;
    EXPECT_EQ(got["iterations"], expected["iterations"]) << name;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(got["tf"][k].get<double>(), expected["tf"][k].get<double>(), 1e-6) << name;
    }
  }
}

TEST_F(Cli, BadInputExitsTwoWithOneLineNamingTheProblem) {
  const std::string sv = R"("supervoxels": [{"position": [0, 0, 1], "normal": [0, 0, -1]}])";
  struct Case {
    std::string args;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases{
      {"estimate " + (dir_ / "absent.json").string(), {"absent.json", "cannot read"}},
      {"estimate " + write("syntax.json", "{\"supervoxels\": [").string(), {"syntax.json", "invalid JSON"}},
      {"estimate " + write("overflow.json", "{" + sv + ", \"occluders\": [[1e999, 0, 0]]}").string(),
       {"overflow.json", "invalid JSON"}},
      {"estimate " + write("empty.json", "{}").string(), {"empty.json", "supervoxels", "missing"}},
      {"estimate " + write("unknown.json", "{" + sv + ", \"colour\": 3}").string(), {"unknown.json", "colour"}},
      {"estimate " + write("type.json", "{\"supervoxels\": [{\"position\": 1, \"normal\": [0,0,1]}]}").string(),
       {"type.json", "supervoxels[0].position", "1"}},
      {"estimate " + write("neg.json", "{" + sv + ", \"params\": {\"r_sphere\": -0.5}}").string(),
       {"neg.json", "r_sphere", "-0.5"}},
      {"estimate " + write("word.json", "{" + sv + ", \"params\": {\"push_weighting\": \"max\"}}").string(),
       {"word.json", "push_weighting", "max"}},
      {"estimate " + write("nosv.json", "{\"supervoxels\": []}").string(), {"nosv.json", "no usable supervoxel"}},
      {"estimate " + write("zeronormal.json", R"({"supervoxels": [{"position": [0, 0, 1], "normal": [0, 0, 0]}],
                                                  "camera": [0, 0, 0]})").string(),
       {"zeronormal.json", "no usable supervoxel", "no centroid"}},
      {"estimate " + write("ok1.json", "{" + sv + "}").string() + " --set speed=3", {"speed", "unknown parameter"}},
      {"estimate " + write("ok2.json", "{" + sv + "}").string() + " --set step=-1", {"step", "-1"}},
      {"estimate " + write("ok3.json", "{" + sv + "}").string() + " --set step", {"--set step", "name=value"}},
      {"estimate", {"scene"}},
      {"estimate a.json b.json", {"b.json"}},
      {"frobnicate", {"frobnicate"}},
      // Hostile documents: deep nesting (it overflowed the stack), repeated keys
      // (the last one won silently), sizes; the message never prints the document.
      {"estimate " + write("deep.json", std::string(100000, '[') + std::string(100000, ']')).string(),
       {"deep.json", "nested deeper than"}},
      {"estimate " + write("deepsv.json", "{\"supervoxels\": " + std::string(100000, '[') + std::string(100000, ']') + "}").string(),
       {"deepsv.json", "nested deeper than"}},
      {"estimate " + write("dup.json", "{" + sv + ", " + sv + "}").string(), {"dup.json", "duplicate key", "supervoxels"}},
      {"estimate " + write("dupin.json", R"({"supervoxels": [{"position": [0, 0, 1], "position": [0, 0, 2], "normal": [0, 0, -1]}]})").string(),
       {"dupin.json", "duplicate key", "position"}},
      {"estimate " + write("long.json", "{\"supervoxels\": [{\"position\": \"" + std::string(20000, '1') + "\", \"normal\": [0, 0, 1]}]}").string(),
       {"long.json", "supervoxels[0].position"}},
      {"estimate " + write("wide.json", "{\"supervoxels\": [{\"position\": [" + [] { std::string a = "0"; for (int k = 0; k < 20000; ++k) a += ", 0"; return a; }() + "], \"normal\": [0, 0, 1]}]}").string(),
       {"wide.json", "supervoxels[0].position", "20001 items"}},
      {"estimate " + write("key.json", "{" + sv + ", \"" + std::string(20000, 'k') + "\": 1}").string(), {"key.json", "unknown key"}},
      {"estimate " + [&] { const fs::path p = write("huge.json", "{}"); fs::resize_file(p, (std::uintmax_t{64} << 20) + 1); return p.string(); }(),
       {"huge.json", "bytes"}},
      // What is not a regular file is refused before it is opened or read:
      // a directory, a device that never ends, a FIFO without a writer
      // (which would block), for every command that reads an input file.
      {"estimate " + dir_.string(), {dir_.string(), "is a directory", "scene"}},
      {"estimate /dev/zero", {"/dev/zero", "not a regular file"}},
      {"estimate " + [&] { const fs::path p = dir_ / "scene.fifo"; ::mkfifo(p.c_str(), 0600); return p.string(); }(),
       {"scene.fifo", "not a regular file"}},
      {"simulate " + dir_.string(), {dir_.string(), "is a directory", "scenario"}},
      {"simulate /dev/zero", {"/dev/zero", "not a regular file", "scenario"}},
      {"compare --scenarios " + std::string(OFV_SOURCE_DIR) + "/sim/scenarios --grid /dev/zero --out " + (dir_ / "sweep").string(),
       {"/dev/zero", "grid"}},
      // Outputs that would replace or mix with other data: a recording into
      // a folder that holds something, a .oni beside a device.
      {"record dvd-static --format tum --out " + [&] { fs::create_directories(dir_ / "used"); write("used/rgb.txt", ""); return (dir_ / "used").string(); }(),
       {"used", "not empty"}},
      {"record dvd-static --format pcd --out " + write("afile", "x").string(), {"afile", "not a directory"}},
      {"record dvd-static --format oni --out /dev/null", {"/dev/null", "not a regular file"}},
  };
  for (const auto& c : cases) {
    const CommandResult r = ofv(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args.substr(0, 200);
    EXPECT_TRUE(r.out.empty()) << c.args.substr(0, 200) << ": " << r.out;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args.substr(0, 200) << ": " << r.err.substr(0, 400);
    EXPECT_LT(r.err.size(), 400u) << c.args.substr(0, 200) << ": " << r.err.substr(0, 400);
    for (const auto& m : c.mentions) {
      EXPECT_NE(r.err.find(m), std::string::npos) << c.args.substr(0, 200) << ": " << r.err.substr(0, 400);
    }
  }
}

}  // namespace

// The exit status of `sh -c COMMAND` run with standard output into a pipe
// whose reader is already gone (`ofv ... | head` once head has left); -1 when killed by a signal.
int exit_code_into_a_closed_pipe(const std::string& command) {
  int fds[2];
  if (pipe(fds) != 0) return -2;
  close(fds[0]);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST_F(Cli, AClosedOutputIsNoKillAndAFullOneIsAnError) {
  const std::string ofv_bin = std::string("\"") + OFV_BINARY + "\" ";
  for (const std::string& args : std::vector<std::string>{"settings", "settings --markdown", "estimate \"" + kExample + "\"", "--help-all"}) {
    EXPECT_EQ(exit_code_into_a_closed_pipe(ofv_bin + args + " 2>/dev/null"), 0) << args;
  }
  const fs::path err = dir_ / "stderr";
  const int status = std::system((ofv_bin + "settings >/dev/full 2>\"" + err.string() + "\"").c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status;
  EXPECT_EQ(slurp(err), "ofv: the output could not be written\n");
}
