// One loop for simulation and robots, end to end through the CLI: `ofv run`
// replays a simulated episode's commands from its recording, and rehearses a
// deployment on ViSP's threaded simulator with a live simulated sensor.
#include "cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace ofv {
namespace {

namespace fs = std::filesystem;

struct Command {
  std::string status;
  std::vector<double> v;
  std::string mode, proposer;  ///< the policy's decision (LoopStep::mode, LoopStep::proposer)
};

// trajectory.csv: status and velocity columns by name.
std::vector<Command> episode_commands(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream h(line);
  for (std::string c; std::getline(h, c, ',');) header.push_back(c);
  std::vector<Command> out;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream r(line);
    for (std::string c; std::getline(r, c, ',');) cells.push_back(c);
    Command c;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) {
      if (header[i] == "status") c.status = cells[i];
      if (header[i] == "mode") c.mode = cells[i];
      if (header[i] == "proposer") c.proposer = cells[i];
      for (const char* name : {"vx", "vy", "vz", "wx", "wy", "wz"}) {
        if (header[i] == name) c.v.push_back(std::stod(cells[i]));
      }
    }
    out.push_back(c);
  }
  return out;
}

// `ofv run --dry-run` JSON lines.
std::vector<Command> dry_run_commands(const std::string& out) {
  std::vector<Command> commands;
  std::stringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto j = nlohmann::json::parse(line);
    commands.push_back({j.at("status").get<std::string>(), j.at("v").get<std::vector<double>>(),
                        j.value("mode", ""), j.value("proposer", "")});
  }
  return commands;
}

double largest_difference(const std::vector<Command>& a, const std::vector<Command>& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
    for (std::size_t i = 0; i < 6; ++i) worst = std::max(worst, std::abs(a[k].v.at(i) - b[k].v.at(i)));
  }
  return worst;
}

TEST(OneLoop, RunReplaysTheCommandsOfASimulatedEpisode) {
  const fs::path dir = fs::path(test::scratch_dir()) / "one_loop";
  const std::string settings = " --set gain=5 --set target_hysteresis=false";
  // select=auto: the object found as `ofv run` finds it in a recording.
  const CommandRun sim = run("simulate dvd-one-hand --set duration=1.5 --set select=auto --no-pictures" + settings + " --out " +
                             (dir / "episode").string() + " --record " + (dir / "frames").string());
  ASSERT_EQ(sim.code, 0) << sim.err;
  const std::vector<Command> episode = episode_commands(dir / "episode" / "trajectory.csv");
  ASSERT_EQ(episode.size(), 46U);

  const CommandRun replay = run("run --robot camera --source " + (dir / "frames").string() + " --dry-run" + settings);
  ASSERT_EQ(replay.code, 0) << replay.err;
  std::vector<Command> commands = dry_run_commands(replay.out);
  ASSERT_EQ(commands.size(), episode.size() + 1);
  EXPECT_EQ(commands.back().status, "stop");  // the final command leaves the robot at rest
  EXPECT_EQ(largest_difference({commands.back()}, {Command{"", std::vector<double>(6, 0.0), "", ""}}), 0.0);
  commands.pop_back();
  for (std::size_t k = 0; k < episode.size(); ++k) {
    EXPECT_EQ(commands[k].status, episode[k].status) << "frame " << k;
    // The same decisions: the mode and the proposer of each frame's target.
    EXPECT_EQ(commands[k].mode, episode[k].mode) << "frame " << k;
    EXPECT_EQ(commands[k].proposer, episode[k].proposer) << "frame " << k;
  }
  EXPECT_LE(largest_difference(commands, episode), 1e-9);

  // Other settings, other commands: the comparison can fail.
  const CommandRun other = run("run --robot camera --source " + (dir / "frames").string() + " --dry-run --set gain=3");
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_GT(largest_difference(dry_run_commands(other.out), episode), 1e-3);
}

TEST(OneLoop, RunTracksTheObjectThatABoxPointsOut) {
  // A recording whose first frame has a hand in front of the case's centre
  // (it leaves from 0.8 s): by default the front end picks the hand, the
  // cluster at the image centre, and loses it when it leaves; a world
  // box around the case makes the case the object, never lost.
  const fs::path dir = fs::path(test::scratch_dir()) / "run_box";
  const std::string scenario = std::string(OFV_SOURCE_DIR) + "/test/data/loop/hand-over-case-at-start.yaml";
  const CommandRun sim = run("simulate " + scenario + " --set method=static --no-pictures --out " +
                             (dir / "episode").string() + " --record " + (dir / "frames").string());
  ASSERT_EQ(sim.code, 0) << sim.err;
  const std::string source = "run --robot camera --dry-run --source " + (dir / "frames").string();
  const auto lost = [](const CommandRun& r) {
    std::size_t n = 0;
    for (const Command& c : dry_run_commands(r.out)) n += c.status == "object_lost" ? 1 : 0;
    return n;
  };
  const CommandRun centre = run(source);
  const CommandRun boxed = run(source + " --box -0.1,-0.075,0.48,0.1,0.075,0.52");
  ASSERT_EQ(centre.code, 0) << centre.err;
  ASSERT_EQ(boxed.code, 0) << boxed.err;
  EXPECT_GT(lost(centre), 5U);
  EXPECT_EQ(lost(boxed), 0U);
  EXPECT_EQ(dry_run_commands(boxed.out).size(), 46U + 1U);

  // Selections that cannot be: exit 2, naming the option.
  const std::vector<std::pair<std::string, std::string>> bad{{" --box 0,0,1,1,1,0", "--box"},
                                                             {" --box 0,0,0,1,1,nan", "--box"},
                                                             {" --rect 0,0,10.5,10", "--rect"},
                                                             {" --box 0,0,0,1,1,1 --rect 0,0,10,10", "--rect"},
                                                             {" --set select=auto", "select"},
                                                             // nothing of the first frame inside
                                                             {" --box 2,2,2,3,3,3", "selects nothing"},
                                                             {" --rect 0,0,2,2", "selects nothing"},
                                                             // a flag and a --set of the same setting
                                                             {" --set robot=viper850", "--robot"}};
  for (const auto& [options, named] : bad) {
    const CommandRun r = run(source + options);
    EXPECT_EQ(r.code, 2) << options;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
  }
  EXPECT_EQ(run("run --robot viper850 --source sim:dvd-one-hand --box 0,0,0,1,1,1").code, 2);
  // A flag and a --set that give one setting two values: one would be ignored.
  for (const char* both : {"simulate dvd-static --seed 1 --set seed=2", "simulate dvd-static --robot camera --set robot=afma6",
                           "simulate dvd-static --perception labels --set perception=full"}) {
    const CommandRun r = run(both);
    EXPECT_EQ(r.code, 2) << both;
    EXPECT_NE(r.err.find("give one"), std::string::npos) << both << ": " << r.err;
  }
  // A calibration a simulated robot would ignore.
  const CommandRun emc = run("run --robot viper850 --source sim:dvd-one-hand --emc /dev/null");
  EXPECT_EQ(emc.code, 2);
  EXPECT_NE(emc.err.find("--emc"), std::string::npos) << emc.err;
  EXPECT_EQ(run(source + " --emc /dev/null").code, 2);
}

TEST(OneLoop, RehearsalRunsInWallClockTimeOnTheThreadedArm) {
  const auto start = std::chrono::steady_clock::now();
  const CommandRun r = run("run --robot viper850 --source sim:dvd-one-hand --set duration=1.5");
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GE(elapsed, 1.5);
  EXPECT_NE(r.out.find("rehearsal of dvd-one-hand on the threaded viper850"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("visible fraction: mean"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("distance to the sphere"), std::string::npos) << r.out;
  EXPECT_EQ(run("run --robot camera --source sim:dvd-one-hand").code, 2);  // no threaded free-flying camera
  EXPECT_EQ(run("run --robot viper850 --source sim:no-such-scenario").code, 2);
}

TEST(OneLoop, TheRehearsalRunsTheSimulationsPolicyWithGroundTruthToo) {
  // In the cage of no-free-view the look-ahead holds the camera or climbs
  // (proposers here, climb): it needs how much of the object each frame
  // shows. With perception=ground-truth both drivers get it from the same
  // observation of the frame (the labels' object voxels), not the
  // simulator's visible fraction, and both look ahead.
  const fs::path dir = fs::path(test::scratch_dir()) / "rehearsal_policy";
  const std::string settings = " --set perception=ground-truth --set duration=1.5";
  const CommandRun sim = run("simulate no-free-view --set robot=viper850 --no-pictures --out " + dir.string() + settings);
  ASSERT_EQ(sim.code, 0) << sim.err;
  const CommandRun rehearsal = run("run --robot viper850 --source sim:no-free-view --dry-run" + settings);
  ASSERT_EQ(rehearsal.code, 0) << rehearsal.err;
  const auto looks_ahead = [](const std::vector<Command>& commands) {
    return std::count_if(commands.begin(), commands.end(),
                         [](const Command& c) { return c.proposer == "here" || c.proposer == "climb"; });
  };
  const auto proposers = [](const std::vector<Command>& commands) {
    std::string list;
    for (const Command& c : commands) list += (c.proposer.empty() ? c.status : c.proposer) + " ";
    return list;
  };
  const std::vector<Command> simulated = episode_commands(dir / "trajectory.csv");
  std::vector<Command> rehearsed = dry_run_commands(rehearsal.out.substr(0, rehearsal.out.find("ofv run:")));
  // The arm runs in wall-clock time: a loaded machine gets as few as two
  // steps before the final stop. Without the frame's shown part (the bug
  // this guards) no step looks ahead.
  ASSERT_FALSE(rehearsed.empty());
  EXPECT_EQ(rehearsed.back().status, "stop");
  rehearsed.pop_back();
  ASSERT_GE(rehearsed.size(), 2U);
  EXPECT_GT(looks_ahead(simulated), static_cast<long>(simulated.size()) / 2) << proposers(simulated);
  EXPECT_GE(2 * looks_ahead(rehearsed), static_cast<long>(rehearsed.size())) << proposers(rehearsed);
}

TEST(OneLoop, RehearsalTracksTheScenariosObject) {
  // As ofv simulate does: the hand over the case in the first frame is not
  // taken for the object (select=labels), unless select=auto asks for the
  // front end's own choice. Off the sphere around the case: a few mm, or
  // the 0.2 m between the hand and the case. The arm runs in wall-clock
  // time, so a slow build (sanitizers: 8 steps instead of 16) lags it by
  // a few cm more; the bounds stay well apart from both.
  const std::string rehearsal = "run --robot viper850 --source sim:" + std::string(OFV_SOURCE_DIR) +
                                "/test/data/loop/hand-over-case-at-start.yaml";
  const auto off_sphere_cm = [](const CommandRun& r) {
    const std::string key = "distance to the sphere: max ";
    const std::size_t at = r.out.find(key);
    return at == std::string::npos ? NAN : std::stod(r.out.substr(at + key.size()));
  };
  const CommandRun labels = run(rehearsal);
  const CommandRun automatic = run(rehearsal + " --set select=auto");
  ASSERT_EQ(labels.code, 0) << labels.err;
  ASSERT_EQ(automatic.code, 0) << automatic.err;
  EXPECT_LT(off_sphere_cm(labels), 6.0) << labels.out;
  EXPECT_GT(off_sphere_cm(automatic), 12.0) << automatic.out;
}

TEST(OneLoop, AClosedOutputStopsTheRunCleanly) {
  // `ofv run --dry-run | head -1`: the reader goes away after one line; the
  // next line fails (EPIPE, not a SIGPIPE kill), the run stops as on a
  // signal, leaves the robot at rest and exits 0, saying why on stderr.
  const auto start = std::chrono::steady_clock::now();
  const CommandRun r = run_into_head("run --robot afma6 --source sim:dvd-one-hand --set duration=30 --dry-run");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 20.0);
  EXPECT_NE(r.err.find("stopped: the output's reader went away"), std::string::npos) << r.err;
}

TEST(OneLoop, SignalsStopTheRobotAndEndTheRun) {
  for (const char* signal : {"INT", "TERM"}) {
    // Like Ctrl-C (INT) or a kill (TERM) 4 s into a 30 s run (start-up included: slow under sanitizers).
    const CommandRun r = shell(std::string("timeout --preserve-status -s ") + signal + " 4 " + OFV_BINARY +
                               " run --robot afma6 --source sim:dvd-one-hand --set duration=30 --dry-run 2>/dev/null");
    EXPECT_EQ(r.code, 0) << signal << ": " << r.err;
    const std::vector<Command> commands = dry_run_commands(r.out.substr(0, r.out.find("ofv run:")));
    ASSERT_FALSE(commands.empty()) << signal;
    EXPECT_EQ(commands.back().status, "stop") << signal;
    EXPECT_NE(r.out.find(", stopped"), std::string::npos) << signal << ": " << r.out;
  }
}

}  // namespace
}  // namespace ofv
