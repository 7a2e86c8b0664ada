// ofv: occlusion-free view estimation and visual servoing.
#include "commands.h"

#include "ofv/version.h"

#include <iostream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  using namespace ofv::cli;
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
      return command.run();
    }
  }
  return kUsage;
}
