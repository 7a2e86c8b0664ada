// Test helper: runs the `ofv` binary and captures its exit code, stdout and stderr.
#pragma once

#include "scratch.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ofv {

/// Exit code (-1 if the command did not exit normally), stdout and stderr of one run.
struct CommandRun {
  int code = -1;
  std::string out;
  std::string err;
};

/// Runs `ofv ARGS` (OFV_BINARY) through the shell.
inline CommandRun run(const std::string& args) {
  const std::filesystem::path err =
      std::filesystem::path(test::scratch_dir()) / "ofv_cli_stderr.txt";
  const std::string command = std::string(OFV_BINARY) + " " + args + " 2>" + err.string();
  CommandRun r;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    return r;
  }
  char buffer[4096];
  std::size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) {
    r.out.append(buffer, n);
  }
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

}  // namespace ofv
