// `ofv record SCENARIO --format oni|tum|pcd --out PATH`: a simulated episode
// exported as a recording that `ofv perceive` (or any OpenNI2/TUM tool) reads.
#include "commands.h"

#include "ofv/sim/renderer.h"
#include "ofv/sim/scenario.h"
#include "ofv/sources/openni2_source.h"
#include "ofv/sources/pcd_sequence.h"
#include "ofv/sources/tum_sequence.h"

#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

namespace ofv::cli {

Command add_record_command(CLI::App& app) {
  struct Options {
    std::string scenario;
    std::string format = "tum";
    std::string out;
    double until = -1.0;
    bool clean = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "record", "Export a simulated episode (scenario from its start camera) as a recording");
  sub->add_option("scenario", opt->scenario, "Scenario file or built-in name (e.g. dvd-one-hand)")
      ->required();
  sub->add_option("--format", opt->format,
                  "oni (OpenNI2 .oni file), tum (TUM RGB-D directory) or pcd")
      ->check(CLI::IsMember({"oni", "tum", "pcd"}));
  sub->add_option("--out", opt->out, "Output .oni file or directory")->required();
  sub->add_option("--until", opt->until,
                  "Stop at this time [s] (default: the scenario's duration)");
  sub->add_flag("--no-noise", opt->clean, "Render without sensor noise");
  sub->footer(
      "The camera stays at the scenario's start pose (closed-loop episodes: 'ofv simulate').\n"
      "Poses go to groundtruth.txt (tum), poses.txt (pcd) or PATH.poses.txt (oni).\n"
      "Exit 0 ok, 1 runtime failure, 2 bad input (one line on stderr).");

  return {sub, [opt]() -> int {
            std::unique_ptr<sim::Scenario> scenario;
            try {
              scenario = std::make_unique<sim::Scenario>(sim::load_scenario(opt->scenario));
            } catch (const std::exception& e) {
              std::cerr << "ofv record: " << e.what() << '\n';
              return kUsage;
            }
            try {
              std::function<void(const RgbdFrame&)> write;
              std::unique_ptr<OniWriter> oni;
              std::unique_ptr<TumSequenceWriter> tum;
              std::unique_ptr<PcdSequenceWriter> pcd;
              if (opt->format == "oni") {
                oni = std::make_unique<OniWriter>(opt->out,
                                                  static_cast<int>(std::lround(scenario->rate)));
                write = [&oni](const RgbdFrame& f) { oni->write(f); };
              } else if (opt->format == "tum") {
                tum = std::make_unique<TumSequenceWriter>(opt->out);
                write = [&tum](const RgbdFrame& f) { tum->write(f); };
              } else {
                pcd = std::make_unique<PcdSequenceWriter>(opt->out);
                write = [&pcd](const RgbdFrame& f) { pcd->write(f); };
              }
              sim::Renderer renderer(*scenario);
              const double end =
                  opt->until >= 0.0 ? std::min(opt->until, scenario->duration) : scenario->duration;
              const long frames = static_cast<long>(std::floor(end * scenario->rate + 1e-9));
              for (long k = 0; k < frames; ++k) {
                const double t = static_cast<double>(k) / scenario->rate;
                renderer.set_time(t);
                sim::RenderedFrame r = renderer.render(scenario->wMc_start, k,
                                                       scenario->sensor.intrinsics, !opt->clean);
                r.frame.timestamp = t;
                write(r.frame);
              }
              if (oni) {
                oni->close();
              }
              std::cerr << "ofv record: " << scenario->name << ": " << frames << " frames to "
                        << opt->out << " (" << opt->format << ")\n";
              return kOk;
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv record: " << e.what() << '\n';
              return kUsage;
            } catch (const std::exception& e) {
              std::cerr << "ofv record: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
