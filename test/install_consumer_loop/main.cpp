// Half a second of the built-in scenario dvd-one-hand with ground-truth
// perception: the installed libofv_sim must find its scenarios by itself.
#include <ofv/loop/episode.h>

#include <cmath>
#include <iostream>

int main() {
  try {
    const ofv::sim::Scenario scenario = ofv::sim::load_scenario("dvd-one-hand");
    const ofv::EpisodeSetup setup =
        ofv::resolve_episode(scenario, {{"duration", "0.5"}, {"perception", "ground-truth"}});
    const ofv::EpisodeOutcome outcome = ofv::run_episode(setup);
    const ofv::EpisodeMetrics& m = outcome.metrics;
    std::cout << "scenarios from " << ofv::sim::builtin_scenario_dir() << "\n"
              << m.steps << " steps over " << m.duration << " s, mean visible fraction "
              << m.mean_visible_fraction << ", " << 100 * m.max_sphere_distance_error
              << " cm off the sphere at most\n";
    const double period = 1.0 / scenario.rate;
    const bool ok = m.steps == static_cast<int>(outcome.steps.size()) && m.steps >= 0.5 / period &&
                    std::abs(m.duration - 0.5) <= period + 1e-9 && m.mean_visible_fraction > 0.5 &&
                    m.mean_visible_fraction <= 1.0 && std::isfinite(m.max_sphere_distance_error);
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "consumer_loop: " << e.what() << '\n';
    return 1;
  }
}
