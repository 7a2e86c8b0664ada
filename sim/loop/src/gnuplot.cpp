// gnuplot by argument vector, in a working directory, without a shell.
#include "gnuplot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <vector>

extern char** environ;

namespace ofv::detail {

std::string gnuplot_string(const std::string& text) {
  std::string out = "'";
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (ch == '\'') {
      out += "''";
    } else if (c < 0x20 || c == 0x7f) {
      out += ' ';
    } else {
      out += ch;
    }
  }
  return out + "'";
}

bool run_gnuplot(const std::filesystem::path& dir, const std::string& script, const std::filesystem::path& log) {
  posix_spawn_file_actions_t actions;
  if (posix_spawn_file_actions_init(&actions) != 0) return false;
  // Opened before the chdir: `log` is relative to our working directory.
  const std::string log_path = log.empty() ? std::string("/dev/null") : log.string();
  const std::string dir_path = dir.string();
  bool ok = posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0) == 0 &&
            posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0) == 0 &&
            posix_spawn_file_actions_addopen(&actions, 2, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644) == 0 &&
            posix_spawn_file_actions_addchdir_np(&actions, dir_path.c_str()) == 0;
  pid_t pid = -1;
  if (ok) {
    std::string program = "gnuplot", argument = script;
    std::vector<char*> argv{program.data(), argument.data(), nullptr};
    ok = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ) == 0;
  }
  posix_spawn_file_actions_destroy(&actions);
  if (!ok) return false;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return false;
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace ofv::detail
