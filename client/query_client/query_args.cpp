#include "query_client/query_args.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace ort::client {

std::vector<double> parse_numbers(const std::string& text, size_t count, char sep) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, sep)) {
    size_t used = 0;
    double x = 0;
    try {
      x = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size())
      throw std::invalid_argument("'" + text + "' is not " + std::to_string(count) + " numbers");
    v.push_back(x);
  }
  if (v.size() != count) throw std::invalid_argument("'" + text + "' is not " + std::to_string(count) + " numbers");
  return v;
}

std::vector<float> parse_points(const std::vector<std::string>& args) {
  std::vector<float> xyz;
  for (const std::string& a : args)
    for (double v : parse_numbers(a, 3)) xyz.push_back(static_cast<float>(v));
  return xyz;
}

std::vector<float> read_points_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("cannot read " + path);
  std::vector<float> xyz;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    for (char& c : line)
      if (c == ',' || c == '\t') c = ' ';
    std::istringstream l(line);
    double x, y, z;
    if (!(l >> x)) continue;  // blank line
    if (!(l >> y >> z)) throw std::invalid_argument(path + ":" + std::to_string(n) + ": not three numbers");
    xyz.insert(xyz.end(), {float(x), float(y), float(z)});
  }
  return xyz;
}

Box parse_box(const std::string& text) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw std::invalid_argument("'" + text + "' is not MINX,MINY,MINZ:MAXX,MAXY,MAXZ");
  const auto lo = parse_numbers(text.substr(0, colon), 3), hi = parse_numbers(text.substr(colon + 1), 3);
  Box b;
  for (int i = 0; i < 3; ++i) b.min[i] = lo[i], b.max[i] = hi[i];
  return b;
}

void parse_range(const std::string& text, double& lo, double& hi) {
  const auto v = parse_numbers(text, 2, ':');
  lo = v[0], hi = v[1];
}

}  // namespace ort::client
