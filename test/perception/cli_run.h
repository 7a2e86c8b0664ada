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

/// Runs a shell command: its exit code (-1 if it did not exit normally or
/// could not start) and stdout; `err` is left empty.
inline CommandRun shell(const std::string& command) {
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
  return r;
}

/// Runs `ofv ARGS` (OFV_BINARY) through the shell.
inline CommandRun run(const std::string& args) {
  const std::filesystem::path err =
      std::filesystem::path(test::scratch_dir()) / "ofv_cli_stderr.txt";
  CommandRun r = shell(std::string(OFV_BINARY) + " " + args + " 2>" + err.string());
  r.err = file_text(err);
  return r;
}

/// `ofv ARGS | head -1`: the reader goes away after the first line. `code`
/// is ofv's exit status (141 when SIGPIPE killed it), `err` its stderr.
inline CommandRun run_into_head(const std::string& args) {
  const std::filesystem::path err =
      std::filesystem::path(test::scratch_dir()) / "ofv_cli_head_stderr.txt";
  CommandRun r = shell(std::string("bash -c '") + OFV_BINARY + " " + args + " 2>" + err.string() +
                       " | head -1 >/dev/null; exit ${PIPESTATUS[0]}'");
  r.err = file_text(err);
  return r;
}

}  // namespace ofv
