// `--box` and `--rect`: the object pointed out in the first frame, for
// `ofv perceive` and `ofv run`.
#include "commands.h"

#include "ofv/perception/perception.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ofv::cli {

namespace {

std::vector<double> parse_numbers(const std::string& text, std::size_t count,
                                  const std::string& option) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(values.back())) {
        throw std::invalid_argument(item);
      }
    } catch (const std::exception&) {
      throw std::invalid_argument(option + " " + text + ": '" + item + "' is not a finite number");
    }
  }
  if (values.size() != count) {
    throw std::invalid_argument(option + " " + text + ": expected " + std::to_string(count) +
                                " comma-separated numbers");
  }
  return values;
}

}  // namespace

void add_selection_options(CLI::App& app, std::string& box, std::string& rect) {
  CLI::Option* by_box = app.add_option("--box", box, "Select the object in frame 0 by a world box [m]")
                            ->type_name("X0,Y0,Z0,X1,Y1,Z1");
  app.add_option("--rect", rect, "Select the object in frame 0 by an image rectangle [px]")
      ->type_name("U0,V0,U1,V1")
      ->excludes(by_box);
}

perception::ObjectSelection object_selection(const std::string& box, const std::string& rect) {
  perception::ObjectSelection selection;
  if (!box.empty()) {
    const auto b = parse_numbers(box, 6, "--box");
    selection.mode = perception::ObjectSelection::Mode::Box;
    selection.box = Eigen::AlignedBox3d(Eigen::Vector3d(b[0], b[1], b[2]), Eigen::Vector3d(b[3], b[4], b[5]));
    if (selection.box.isEmpty()) {
      throw std::invalid_argument("--box " + box + ": empty (needs X0 <= X1, Y0 <= Y1, Z0 <= Z1)");
    }
  } else if (!rect.empty()) {
    const auto b = parse_numbers(rect, 4, "--rect");
    for (const double v : b) {
      if (!(std::abs(v) < 1e6) || v != std::floor(v)) {
        throw std::invalid_argument("--rect " + rect + ": pixels are whole numbers");
      }
    }
    selection.mode = perception::ObjectSelection::Mode::Image;
    selection.rect = Eigen::AlignedBox2i(Eigen::Vector2i(static_cast<int>(b[0]), static_cast<int>(b[1])),
                                         Eigen::Vector2i(static_cast<int>(b[2]), static_cast<int>(b[3])));
    if (selection.rect.isEmpty()) {
      throw std::invalid_argument("--rect " + rect + ": empty (needs U0 <= U1, V0 <= V1)");
    }
  }
  return selection;
}

}  // namespace ofv::cli
