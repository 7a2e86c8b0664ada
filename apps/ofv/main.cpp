// ofv: occlusion-free view estimation and visual servoing.
#include "commands.h"

#include "ofv/version.h"

#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <iostream>
#include <string>
#include <vector>

namespace {

// Whether standard output is a pipe whose reader has gone (`ofv ... | head`).
bool output_reader_gone() {
  struct stat st {};
  if (fstat(STDOUT_FILENO, &st) != 0 || !S_ISFIFO(st.st_mode)) return false;
  pollfd out{STDOUT_FILENO, 0, 0};
  return poll(&out, 1, 0) == 1 && (out.revents & POLLERR) != 0;
}

// A command's exit code once its output is flushed: a reader that stopped
// reading took what it wanted (as with a Unix tool under `| head`, nothing
// more is said); any other failed write is an error.
int finish_output(int code) {
  if (std::cout.flush() || output_reader_gone()) return code;
  std::cerr << "ofv: the output could not be written\n";
  return code != ofv::cli::kOk ? code : ofv::cli::kRuntimeFailure;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace ofv::cli;
  // A closed output is a write error the commands see (`ofv run` stops the
  // robot on it), never a kill.
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{
      "ofv - occlusion-free view: keep a target object in clear view of an eye-in-hand RGB-D\n"
      "camera (Cuiral-Zueco & Lopez-Nicolas, \"Dynamic Occlusion Handling for Real Time\n"
      "Object Perception\"). Run 'ofv COMMAND --help' for a command's options."};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Print the help of every command");
  app.set_version_flag("--version", std::string("ofv ") + ofv::version() + " (git " + ofv::git_commit() + ")");

  std::vector<Command> commands;
#ifdef OFV_HAVE_LOOP  // built with the simulator, the servo library and perception
  commands.push_back(add_simulate_command(app));
  commands.push_back(add_compare_command(app));
  commands.push_back(add_run_command(app));
  commands.push_back(add_render_command(app));
#endif
  commands.push_back(add_estimate_command(app));
  commands.push_back(add_settings_command(app));
#ifdef OFV_HAVE_PERCEPTION  // built with the perception front end (OFV_BUILD_PERCEPTION)
  commands.push_back(add_perceive_command(app));
#endif
#ifdef OFV_HAVE_RECORD  // built with the simulator and the perception sources
  commands.push_back(add_record_command(app));
#endif
  app.footer(estimator_settings_help());

  std::string known;
  bool listed = argc < 2 || argv[1][0] == '-';
  for (const Command& command : commands) {
    known += (known.empty() ? "" : ", ") + command.app->get_name();
    listed = listed || command.app->get_name() == argv[1];
  }
  if (!listed) {
    std::cerr << "ofv: unknown command '" << argv[1] << "' (commands: " << known << ")\n";
    return kUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "ofv: " << e.what() << " (see 'ofv --help')\n";
    return kUsage;
  }
  for (const Command& command : commands) {
    if (command.app->parsed()) {
      return finish_output(command.run());
    }
  }
  return kUsage;
}
