#include "scene/real_map_world.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <octomap/OcTree.h>

namespace ort::scene {
namespace {

std::unique_ptr<octomap::OcTree> read_tree(const std::string& path) {
  if (!std::ifstream(path)) throw std::runtime_error("cannot open map '" + path + "'");
  std::unique_ptr<octomap::OcTree> tree;
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".bt") == 0) {
    tree = std::make_unique<octomap::OcTree>(0.1);
    if (!tree->readBinary(path)) tree.reset();
  } else {
    tree.reset(dynamic_cast<octomap::OcTree*>(octomap::AbstractOcTree::read(path)));
  }
  if (!tree || tree->size() == 0) throw std::runtime_error("'" + path + "' is not a readable OcTree");
  return tree;
}

// Breadth-first search over a 2D lattice of usable cells (4-neighbours): distances and parents.
void bfs(const std::vector<char>& ok, int nx, int ny, int start, std::vector<int>& dist, std::vector<int>& parent) {
  dist.assign(ok.size(), -1);
  parent.assign(ok.size(), -1);
  std::deque<int> q{start};
  dist[start] = 0;
  while (!q.empty()) {
    const int c = q.front();
    q.pop_front();
    const int x = c % nx, y = c / nx;
    const int nb[4][2] = {{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}};
    for (const auto& n : nb) {
      if (n[0] < 0 || n[1] < 0 || n[0] >= nx || n[1] >= ny) continue;
      const int k = n[1] * nx + n[0];
      if (!ok[k] || dist[k] >= 0) continue;
      dist[k] = dist[c] + 1;
      parent[k] = c;
      q.push_back(k);
    }
  }
}

}  // namespace

World make_world_from_octomap(const std::string& map_path, double sensor_height) {
  const auto tree = read_tree(map_path);
  const double res = tree->getResolution();
  double x0, y0, z0, x1, y1, z1;
  tree->getMetricMin(x0, y0, z0);
  tree->getMetricMax(x1, y1, z1);

  World w;
  OccupancyGrid& g = w.scene.grid;
  w.scene.use_grid = true;
  g.voxel = res;
  g.lo = {x0, y0, z0};
  g.dims[0] = int(std::lround((x1 - x0) / res));
  g.dims[1] = int(std::lround((y1 - y0) / res));
  g.dims[2] = int(std::lround((z1 - z0) / res));
  g.bits.assign((uint64_t(g.dims[0]) * g.dims[1] * g.dims[2] + 63) / 64, 0);
  // Known-free columns at sensor height, for the path; occupied voxels, for the geometry.
  const double floor_z = z0, zs = floor_z + sensor_height;
  const double lattice = 0.4;
  const int nx = int((x1 - x0) / lattice) + 1, ny = int((y1 - y0) / lattice) + 1;
  std::vector<int> free_votes(size_t(nx) * ny, 0);
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    const double half = 0.5 * it.getSize();
    const int span = std::max(1, int(std::lround(it.getSize() / res)));
    const int cx = int(std::lround((it.getX() - half - x0) / res)),
              cy = int(std::lround((it.getY() - half - y0) / res)),
              cz = int(std::lround((it.getZ() - half - z0) / res));
    if (tree->isNodeOccupied(*it)) {
      for (int z = cz; z < cz + span; ++z)
        for (int y = cy; y < cy + span; ++y)
          for (int x = cx; x < cx + span; ++x)
            if (x >= 0 && y >= 0 && z >= 0 && x < g.dims[0] && y < g.dims[1] && z < g.dims[2]) g.set(x, y, z);
    } else if (std::abs(it.getZ() - zs) <= half + 0.3) {
      // a large (pruned) free leaf votes for every lattice cell under it
      const int lx0 = std::max(0, int((it.getX() - half - x0) / lattice)),
                lx1 = std::min(nx - 1, int((it.getX() + half - x0) / lattice));
      const int ly0 = std::max(0, int((it.getY() - half - y0) / lattice)),
                ly1 = std::min(ny - 1, int((it.getY() + half - y0) / lattice));
      for (int ly = ly0; ly <= ly1; ++ly)
        for (int lx = lx0; lx <= lx1; ++lx) free_votes[size_t(ly) * nx + lx] += 1;
    }
  }
  // Usable lattice cells: seen free at sensor height and 0.2 m away from anything occupied
  // (FR-079 has narrow passages in its corridor; a wider berth cuts the corridor in two).
  std::vector<char> ok(free_votes.size(), 0);
  for (int ly = 0; ly < ny; ++ly)
    for (int lx = 0; lx < nx; ++lx) {
      if (free_votes[size_t(ly) * nx + lx] == 0) continue;
      const Vec3 p{x0 + (lx + 0.5) * lattice, y0 + (ly + 0.5) * lattice, zs};
      ok[size_t(ly) * nx + lx] = !inside_solid(w.scene, p, 0.2);
    }
  // Start in the largest connected patch of usable cells (small pockets of seen-free space
  // lie outside the building), then take the longest shortest walk in it (two BFS sweeps):
  // in a corridor building, the corridor.
  std::vector<int> dist, parent;
  int start = -1, best_size = 0;
  std::vector<char> seen(ok.size(), 0);
  for (size_t c = 0; c < ok.size(); ++c) {
    if (!ok[c] || seen[c]) continue;
    bfs(ok, nx, ny, int(c), dist, parent);
    int size = 0;
    for (size_t k = 0; k < dist.size(); ++k)
      if (dist[k] >= 0) seen[k] = 1, ++size;
    if (size > best_size) best_size = size, start = int(c);
  }
  if (start < 0) throw std::runtime_error("'" + map_path + "' has no free space at sensor height");
  bfs(ok, nx, ny, start, dist, parent);
  const int a = int(std::max_element(dist.begin(), dist.end()) - dist.begin());
  bfs(ok, nx, ny, a, dist, parent);
  int b = int(std::max_element(dist.begin(), dist.end()) - dist.begin());
  std::vector<int> cells;
  for (int c = b; c >= 0; c = parent[c]) cells.push_back(c);
  // Every fifth lattice step keeps the heading smooth.
  for (size_t i = 0; i < cells.size(); i += 5) {
    const int c = cells[i];
    w.path.push_back({x0 + (c % nx + 0.5) * lattice, y0 + (c / nx + 0.5) * lattice, zs});
  }
  if (cells.size() > 1 && (cells.size() - 1) % 5 != 0) {
    const int c = cells.back();
    w.path.push_back({x0 + (c % nx + 0.5) * lattice, y0 + (c / nx + 0.5) * lattice, zs});
  }
  w.lo = g.lo;
  w.hi = {x1, y1, z1};
  w.boxes = 0;
  return w;
}

}  // namespace ort::scene
