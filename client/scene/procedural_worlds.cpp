#include "scene/procedural_worlds.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "scene/world_parts.h"

namespace ort::scene {
namespace {

using namespace world_parts;

// ---- indoor building ---------------------------------------------------------------------

struct Door {
  double x0, x1;  // gap along the wall
  bool open;
};

struct Room {
  double x0, y0, x1, y1;  // interior
  double door_x;          // door centre
  double door_wall_y;     // y of the wall face on the corridor side
  int corridor = -1;      // index of the corridor the door opens on
  bool door_open = true;
};

// A wall along x at y in [y0, y1] (thickness) from xa to xb, with door gaps.
void wall_along_x(std::vector<Box>& out, double xa, double xb, double y0, double y1, double h, std::vector<Door> doors,
                  double door_h) {
  std::sort(doors.begin(), doors.end(), [](const Door& a, const Door& b) { return a.x0 < b.x0; });
  double x = xa;
  for (const Door& d : doors) {
    if (d.x0 > x) out.push_back(box(x, y0, 0, d.x0, y1, h));
    out.push_back(box(d.x0, y0, door_h, d.x1, y1, h));                      // lintel
    if (!d.open) out.push_back(box(d.x0, y0, 0, d.x1, y0 + 0.05, door_h));  // closed door leaf
    x = d.x1;
  }
  if (xb > x) out.push_back(box(x, y0, 0, xb, y1, h));
}

void furnish_room(std::vector<Box>& out, Rng& rng, const Room& r, double sensor_clear) {
  const double cx = 0.5 * (r.x0 + r.x1), cy = 0.5 * (r.y0 + r.y1);
  // Keep the robot's way in (door -> centre) and the centre itself clear.
  const std::vector<Rect> clear = {
      {r.door_x - 0.8, std::min(r.door_wall_y, cy), r.door_x + 0.8, std::max(r.door_wall_y, cy)},
      {cx - sensor_clear, cy - sensor_clear, cx + sensor_clear, cy + sensor_clear},
      {std::min(r.door_x, cx) - 0.8, cy - 0.8, std::max(r.door_x, cx) + 0.8, cy + 0.8}};
  std::vector<Rect> placed;
  const int want = rng.integer(3, 8);
  for (int attempt = 0; attempt < 60 && int(placed.size()) < want; ++attempt) {
    const int kind = rng.integer(0, 3);  // 0 shelf, 1 desk, 2 cabinet, 3 free-standing table
    double len, depth, height;
    switch (kind) {
      case 0:
        len = rng.uniform(0.8, 2.0);
        depth = 0.4;
        height = rng.uniform(1.6, 2.2);
        break;
      case 1:
        len = rng.uniform(1.2, 1.8);
        depth = 0.8;
        height = 0.75;
        break;
      case 2:
        len = rng.uniform(0.5, 1.0);
        depth = 0.6;
        height = rng.uniform(0.8, 1.3);
        break;
      default:
        len = rng.uniform(1.2, 2.4);
        depth = rng.uniform(0.8, 1.2);
        height = 0.74;
        break;
    }
    Rect f;
    if (kind == 3) {
      const double x = rng.uniform(r.x0 + 0.8, r.x1 - 0.8 - len), y = rng.uniform(r.y0 + 0.8, r.y1 - 0.8 - depth);
      f = {x, y, x + len, y + depth};
    } else {
      const int side = rng.integer(0, 3);  // against one of the four walls
      if (side < 2) {
        const double x = rng.uniform(r.x0, r.x1 - len);
        f = side == 0 ? Rect{x, r.y0, x + len, r.y0 + depth} : Rect{x, r.y1 - depth, x + len, r.y1};
      } else {
        const double y = rng.uniform(r.y0, r.y1 - len);
        f = side == 2 ? Rect{r.x0, y, r.x0 + depth, y + len} : Rect{r.x1 - depth, y, r.x1, y + len};
      }
    }
    if (f.x0 < r.x0 || f.x1 > r.x1 || f.y0 < r.y0 || f.y1 > r.y1) continue;
    bool ok = true;
    for (const Rect& c : clear) ok = ok && !f.overlaps(c);
    for (const Rect& p : placed) ok = ok && !f.overlaps(p, 0.1);
    if (!ok) continue;
    placed.push_back(f);
    if (kind == 1 || kind == 3) {  // a table top on four legs: free space underneath
      out.push_back(box(f.x0, f.y0, height - 0.04, f.x1, f.y1, height));
      const double l = 0.05;
      out.push_back(box(f.x0, f.y0, 0, f.x0 + l, f.y0 + l, height - 0.04));
      out.push_back(box(f.x1 - l, f.y0, 0, f.x1, f.y0 + l, height - 0.04));
      out.push_back(box(f.x0, f.y1 - l, 0, f.x0 + l, f.y1, height - 0.04));
      out.push_back(box(f.x1 - l, f.y1 - l, 0, f.x1, f.y1, height - 0.04));
    } else {
      out.push_back(box(f.x0, f.y0, 0, f.x1, f.y1, height));
    }
  }
}

}  // namespace

World make_indoor_building(uint64_t seed, const IndoorParams& p) {
  Rng rng{seed * 0x2545f4914f6cdd1dull + 1};
  const double L = p.length, D = p.width, H = p.height, t = p.wall, cw = p.corridor_width;
  std::vector<Box> boxes;
  boxes.push_back(box(-t, -t, -0.2, L + t, D + t, 0));     // floor
  boxes.push_back(box(-t, -t, H, L + t, D + t, H + 0.2));  // ceiling
  boxes.push_back(box(-t, -t, 0, L + t, 0, H));            // outer walls
  boxes.push_back(box(-t, D, 0, L + t, D + t, H));
  boxes.push_back(box(-t, 0, 0, 0, D, H));
  boxes.push_back(box(L, 0, 0, L + t, D, H));

  std::vector<double> cy;  // corridor centres (along x)
  for (int k = 0; k < p.corridors_x; ++k) cy.push_back(D * (k + 1) / (p.corridors_x + 1) + rng.uniform(-1.0, 1.0));
  std::vector<double> cx;  // cross corridor centres (along y)
  for (int j = 0; j < p.corridors_y; ++j)
    cx.push_back(L * (j + 1) / (p.corridors_y + 1) + rng.uniform(-L / 10, L / 10));

  // Bands between x-corridors, segments between y-corridors: each (band, segment) is a block of rooms.
  std::vector<std::pair<double, double>> bands, segments;
  {
    double y = 0;
    for (double c : cy) {
      bands.push_back({y, c - cw / 2});
      y = c + cw / 2;
    }
    bands.push_back({y, D});
    double x = 0;
    for (double c : cx) {
      segments.push_back({x, c - cw / 2});
      x = c + cw / 2;
    }
    segments.push_back({x, L});
  }
  std::vector<Room> rooms;
  for (size_t b = 0; b < bands.size(); ++b) {
    const auto [y0, y1] = bands[b];
    const bool corr_below = b > 0, corr_above = b + 1 < bands.size();
    for (const auto& [x0, x1] : segments) {
      // cross-corridor walls, no doors
      if (x0 > 0) boxes.push_back(box(x0, y0, 0, x0 + t, y1, H));
      if (x1 < L) boxes.push_back(box(x1 - t, y0, 0, x1, y1, H));
      std::vector<double> cuts = {x0};
      for (double x = x0;;) {
        const double w = rng.uniform(3.5, 7.5);
        if (x1 - (x + w) < 3.5) break;
        x += w;
        cuts.push_back(x);
      }
      cuts.push_back(x1);
      std::vector<Door> below, above;
      for (size_t r = 0; r + 1 < cuts.size(); ++r) {
        const double rx0 = cuts[r], rx1 = cuts[r + 1];
        if (r > 0) boxes.push_back(box(rx0 - t / 2, y0, 0, rx0 + t / 2, y1, H));  // between rooms
        Room room;
        room.x0 = rx0 + (r == 0 && x0 > 0 ? t : t / 2);
        room.x1 = rx1 - (r + 2 == cuts.size() && x1 < L ? t : t / 2);
        room.y0 = y0 + (corr_below ? t : 0);
        room.y1 = y1 - (corr_above ? t : 0);
        if (r == 0 && x0 == 0) room.x0 = rx0;
        if (r + 2 == cuts.size() && x1 == L) room.x1 = rx1;
        const bool use_below = corr_below && (!corr_above || rng.chance(0.5));
        if (!corr_below && !corr_above) {
          rooms.push_back(room);
          continue;
        }
        const double dx = rng.uniform(room.x0 + 0.3, room.x1 - 0.3 - p.door_width);
        room.door_x = dx + p.door_width / 2;
        room.door_open = !rng.chance(p.closed_door_share);
        const Door door{dx, dx + p.door_width, room.door_open};
        if (use_below) {
          below.push_back(door);
          room.door_wall_y = y0 + t;
          room.corridor = int(b) - 1;
        } else {
          above.push_back(door);
          room.door_wall_y = y1 - t;
          room.corridor = int(b);
        }
        rooms.push_back(room);
      }
      if (corr_below) wall_along_x(boxes, x0, x1, y0, y0 + t, H, below, p.door_height);
      if (corr_above) wall_along_x(boxes, x0, x1, y1 - t, y1, H, above, p.door_height);
    }
  }
  for (const Room& r : rooms) furnish_room(boxes, rng, r, 1.0);

  // Pick the rooms the robot enters.
  std::vector<int> visit(rooms.size(), 0);
  {
    std::vector<int> open;
    for (size_t i = 0; i < rooms.size(); ++i)
      if (rooms[i].corridor >= 0 && rooms[i].door_open) open.push_back(int(i));
    for (int v = 0; v < p.room_visits && !open.empty(); ++v) {
      const int k = rng.integer(0, int(open.size()) - 1);
      visit[open[k]] = 1;
      open.erase(open.begin() + k);
    }
  }
  // Serpentine tour: each corridor end to end, joined through the cross corridor nearest the
  // end just reached; rooms are entered on the way past their doors.
  const double z = p.sensor_height;
  Path path;
  auto walk = [&](int k, double xa, double xb) {
    std::vector<int> on;
    for (size_t i = 0; i < rooms.size(); ++i)
      if (visit[i] && rooms[i].corridor == k && std::min(xa, xb) < rooms[i].door_x &&
          rooms[i].door_x < std::max(xa, xb))
        on.push_back(int(i));
    std::sort(on.begin(), on.end(), [&](int a, int b) {
      return xa < xb ? rooms[a].door_x < rooms[b].door_x : rooms[a].door_x > rooms[b].door_x;
    });
    path.push_back({xa, cy[k], z});
    for (int i : on) {
      const Room& r = rooms[i];
      visit[i] = 0;
      const double inside = r.door_wall_y + (r.door_wall_y > cy[k] ? 0.6 : -0.6);
      const Vec3 a{r.door_x, cy[k], z}, b{r.door_x, inside, z}, c{0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1), z};
      path.insert(path.end(), {a, b, {r.door_x, c.y, z}, c, {r.door_x, c.y, z}, b, a});
    }
    path.push_back({xb, cy[k], z});
  };
  const double xw = 1.0, xe = L - 1.0;
  for (int k = 0; k < int(cy.size()); ++k) {
    const bool east = k % 2 == 0;
    if (k == 0) {
      walk(0, xw, xe);
    } else {
      // from the end of corridor k-1 back to the nearest cross corridor, across, then both ways
      const double end = east ? xw : xe;
      double j = cx.empty() ? end : cx[0];
      for (double c : cx)
        if (std::abs(c - end) < std::abs(j - end)) j = c;
      path.push_back({j, cy[k - 1], z});
      path.push_back({j, cy[k], z});
      walk(k, j, east ? xw : xe);
      walk(k, east ? xw : xe, east ? xe : xw);
    }
  }
  return finish(std::move(boxes), std::move(path), 0.5);
}

}  // namespace ort::scene
