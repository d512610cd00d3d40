// Procedural worlds made of boxes, deterministic from a seed: an indoor building (corridors,
// rooms, doors, furniture) and an outdoor campus (roads, buildings, trees, cars, lamp posts).
// Each comes with a collision-free robot path through it at sensor height.
#pragma once

#include <cstdint>
#include <string>

#include "scene/scene_geometry.h"
#include "scene/trajectory.h"

namespace ort::scene {

struct World {
  Scene scene;
  Path path;    // one tour through the world; robots share it out (see scene_presets)
  Vec3 lo, hi;  // extent of the world's geometry
  size_t boxes = 0;
};

struct IndoorParams {
  double length = 46.0, width = 36.0, height = 4.5;  // building extent (x, y, z) [m]
  int corridors_x = 2;                               // corridors along x, evenly spaced in y
  int corridors_y = 1;                               // cross corridors along y
  double corridor_width = 2.4;
  double wall = 0.15;  // wall thickness
  double door_width = 1.0, door_height = 2.1;
  double closed_door_share = 0.25;
  int room_visits = 4;  // rooms the path enters (through open doors)
  double sensor_height = 1.0;
};

struct CampusParams {
  double length = 292.0, width = 167.0;  // ground extent (x, y)
  int roads_x = 3;                       // roads along x (evenly spaced in y, edges included)
  int roads_y = 5;                       // roads along y
  double road_width = 8.0;
  double min_building_height = 8.0, max_building_height = 26.0;
  double tree_spacing = 12.0;  // along roads
  double sensor_height = 1.5;
};

World make_indoor_building(uint64_t seed, const IndoorParams& p);
World make_outdoor_campus(uint64_t seed, const CampusParams& p);

}  // namespace ort::scene
