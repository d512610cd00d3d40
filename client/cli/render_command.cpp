// `octomap-rt render FILE.bt|FILE.ot -o map.png [--view top|oblique] [--z MIN:MAX]`: a
// picture of a map file. The drawing is client/render/; this file only parses flags.
#include <chrono>
#include <iostream>
#include <map>

#include "cli/commands.h"
#include "core/clock.h"
#include "core/log.h"
#include "render/map_file.h"
#include "render/map_render.h"
#include "render/png_file.h"

namespace ort::cli {
namespace {

struct RenderArgs {
  std::string input, output, z_range;
  render::RenderOptions options;
};

std::optional<double> parse_limit(const std::string& text, const std::string& whole) {
  if (text.empty()) return std::nullopt;
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size())
    throw CLI::ValidationError("--z", "expected MIN:MAX in metres (either may be empty), got " + whole);
  return v;
}

render::HeightRange parse_z_range(const std::string& text) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw CLI::ValidationError("--z", "expected MIN:MAX in metres, got " + text);
  render::HeightRange r{parse_limit(text.substr(0, colon), text), parse_limit(text.substr(colon + 1), text)};
  if (r.min && r.max && !(*r.min < *r.max)) throw CLI::ValidationError("--z", "MIN must be below MAX: " + text);
  return r;
}

int run_render(RenderArgs a) {
  if (!a.z_range.empty()) a.options.heights = parse_z_range(a.z_range);
  const auto t0 = SteadyClock::now();
  const auto tree = render::load_map_file(a.input);
  const double load_ms = ms_since(t0);
  const render::MapPicture picture = render::render_map(*tree, a.options);
  render::write_png(picture.canvas, a.output);
  const auto& s = picture.stats;
  log_to(std::cerr, "octomap-rt render")
      .info(text(a.output, " (", picture.canvas.width(), " x ", picture.canvas.height(), " px, ",
                 picture.camera.pixels_per_metre(), " px/m): ", s.occupied_boxes, " occupied, ", s.free_boxes,
                 " free leaves; load ", load_ms, " ms, collect ", s.collect_ms, " ms, raster ", s.raster_ms, " ms"));
  return 0;
}

}  // namespace

void register_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Draw a map file (.bt/.ot) as a PNG picture");
  cmd->add_option("map", args->input, "Map file: OctoMap binary (.bt) or full (.ot)")->required();
  cmd->add_option("-o,--output", args->output, "PNG file to write")->required();
  const std::map<std::string, render::View> views{{"top", render::View::top}, {"oblique", render::View::oblique}};
  cmd->add_option("--view", args->options.view, "top (straight down) or oblique (3D, from above at an angle)")
      ->transform(CLI::CheckedTransformer(views).description(""))
      ->option_text("{top,oblique}");
  cmd->add_option("--z", args->z_range, "Height range MIN:MAX [m] to draw (and colour by); either side may be empty");
  const std::map<std::string, render::FreeSpace> free{{"faint", render::FreeSpace::faint},
                                                      {"hidden", render::FreeSpace::hidden}};
  cmd->add_option("--free", args->options.free, "Free space: faint (footprint on the floor) or hidden")
      ->transform(CLI::CheckedTransformer(free).description(""))
      ->option_text("{faint,hidden}");
  cmd->add_option("--width", args->options.width, "Picture width [px]")->check(CLI::Range(200, 20000));
  cmd->add_option("--azimuth", args->options.azimuth_deg, "Oblique view: camera direction [deg from +x, ccw]");
  cmd->add_option("--elevation", args->options.elevation_deg, "Oblique view: camera elevation [deg]")
      ->check(CLI::Range(5.0, 90.0));
  cmd->callback([args] { run_render(*args); });
}

}  // namespace ort::cli
