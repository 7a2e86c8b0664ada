// `ofv settings [--markdown]`: every setting of ofv simulate, ofv run, ofv
// compare and scenario files, from the settings tables.
#include "commands.h"

#include "ofv/estimator_settings.h"
#ifdef OFV_HAVE_LOOP
#include "ofv/loop/episode.h"
#endif

#include <iostream>

namespace ofv::cli {

Command add_settings_command(CLI::App& app) {
  auto markdown = std::make_shared<bool>(false);
  CLI::App* sub = app.add_subcommand("settings", "List every setting: name, type, default, unit, meaning");
  sub->add_flag("--markdown", *markdown, "As a Markdown table (docs/settings.md)");
  return {sub, [markdown]() -> int {
#ifdef OFV_HAVE_LOOP
            const auto docs = episode_settings_table().docs();
#else
            const auto docs = estimator_settings_table().docs();
#endif
            std::cout << (*markdown ? settings_markdown(docs) : settings_help(docs));
            return kOk;
          }};
}

}  // namespace ofv::cli
