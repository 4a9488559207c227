#include "core/structure/fe_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace dem2d {
namespace {

constexpr double kTurn = 2.0 * std::numbers::pi;

// The element of a structured block whose corner (-1,-1) is grid node (i, j) of `at`.
std::array<int, 9> block_element(const std::function<int(int, int)>& at, int i, int j) {
  return {at(i, j),         at(i + 2, j),     at(i + 2, j + 2), at(i, j + 2),    at(i + 1, j),
          at(i + 2, j + 1), at(i + 1, j + 2), at(i, j + 1),     at(i + 1, j + 1)};
}

int divisions(double length, double size) {
  return std::max(1, static_cast<int>(std::ceil(length / size - 1e-9)));
}

// The ring's angular spans: under each bar and between bars, in counter-clockwise order from
// the first bar's trailing foot. Each span: its start angle, its length, its element count and
// the bar standing on it (-1 for a gap).
struct Span {
  double start = 0.0, length = 0.0;
  int elements = 0, bar = -1;
};

std::vector<Span> ring_spans(double radius, const std::vector<FeBar>& bars, double size) {
  std::vector<Span> spans;
  if (bars.empty()) {
    spans.push_back({0.0, kTurn, std::max(8, divisions(kTurn * radius, size)), -1});
    return spans;
  }
  std::vector<std::pair<double, int>> feet;  // trailing foot angle, bar
  for (std::size_t b = 0; b < bars.size(); ++b) {
    if (bars[b].half_width <= 0.0 || bars[b].half_width >= radius || bars[b].top >= radius)
      throw std::invalid_argument("shell_mesh: bar " + std::to_string(b) +
                                  " does not stand inside the shell");
    const double a = bars[b].phi - std::asin(bars[b].half_width / radius);
    feet.emplace_back(a - kTurn * std::floor(a / kTurn), static_cast<int>(b));
  }
  std::sort(feet.begin(), feet.end());
  const double origin = feet.front().first;
  for (std::size_t k = 0; k < feet.size(); ++k) {
    const FeBar& bar = bars[static_cast<std::size_t>(feet[k].second)];
    const double start = feet[k].first;
    const double arc = 2.0 * std::asin(bar.half_width / radius);
    const double next = k + 1 < feet.size() ? feet[k + 1].first : origin + kTurn;
    const double gap = next - (start + arc);
    if (gap < -1e-12 * radius)
      throw std::invalid_argument("shell_mesh: the feet of two bars overlap on the shell");
    spans.push_back({start, arc, divisions(arc * radius, size), feet[k].second});
    if (gap > 1e-9 * kTurn) spans.push_back({start + arc, gap, divisions(gap * radius, size), -1});
  }
  return spans;
}

// The bar standing on the ring nodes first .. first + 2 m (angular index) of the inner surface.
void add_bar(FeMesh& mesh, FeBar bar, int bar_index, const std::vector<int>& foot, double size) {
  const Vec2 radial{std::cos(bar.phi), std::sin(bar.phi)};
  const Vec2 side = perp(radial);
  const int columns = static_cast<int>(foot.size());  // 2 m + 1
  const double height = dot(mesh.nodes[static_cast<std::size_t>(foot[0])], radial) - bar.top;
  const int nh = divisions(height, size);
  std::vector<int> grid(static_cast<std::size_t>(columns * (2 * nh + 1)));
  for (int i = 0; i < columns; ++i) {
    const Vec2 b = mesh.nodes[static_cast<std::size_t>(foot[static_cast<std::size_t>(i)])];
    const Vec2 t = bar.top * radial + dot(b, side) * side;
    grid[static_cast<std::size_t>(i)] = foot[static_cast<std::size_t>(i)];
    for (int k = 1; k <= 2 * nh; ++k) {
      const double u = static_cast<double>(k) / (2 * nh);
      grid[static_cast<std::size_t>(k * columns + i)] = static_cast<int>(mesh.nodes.size());
      bar.nodes.push_back(static_cast<int>(mesh.nodes.size()));
      mesh.nodes.push_back((1.0 - u) * b + u * t);
    }
  }
  const auto at = [&](int i, int k) { return grid[static_cast<std::size_t>(k * columns + i)]; };
  for (int k = 0; k + 2 < 2 * nh + 1; k += 2)
    for (int i = 0; i + 2 < columns; i += 2) {
      bar.elements.push_back(static_cast<int>(mesh.elements.size()));
      mesh.elements.push_back(block_element(at, i, k));
      mesh.element_bar.push_back(bar_index);
    }
  for (int k = 0; k + 2 <= 2 * nh; k += 2) {
    mesh.loaded_edges.push_back({{at(0, k), at(0, k + 1), at(0, k + 2)}, bar_index, 0});
  }
  for (int i = 0; i + 2 < columns; i += 2)
    mesh.loaded_edges.push_back(
        {{at(i, 2 * nh), at(i + 1, 2 * nh), at(i + 2, 2 * nh)}, bar_index, 1});
  for (int k = 2 * nh; k - 2 >= 0; k -= 2)
    mesh.loaded_edges.push_back(
        {{at(columns - 1, k), at(columns - 1, k - 1), at(columns - 1, k - 2)}, bar_index, 2});
  for (int i = 0; i < columns; ++i) bar.top_nodes.push_back(at(i, 2 * nh));
  bar.tip_node = at(columns / 2, 2 * nh);
  bar.foot = dot(mesh.nodes[static_cast<std::size_t>(foot[0])], radial);
  mesh.bars[static_cast<std::size_t>(bar_index)] = std::move(bar);
}

}  // namespace

FeMesh shell_mesh(double radius, const std::vector<FeBar>& bars, const ShellMeshSpec& spec) {
  if (!(radius > 0.0) || !(spec.thickness > 0.0) || !(spec.element_size > 0.0) ||
      spec.elements_through_thickness < 1)
    throw std::invalid_argument(
        "shell_mesh: radius, thickness and element size must be positive, and at least one "
        "element through the thickness");
  const std::vector<Span> spans = ring_spans(radius, bars, spec.element_size);
  std::vector<double> angle;  // the ring's node angles, counter-clockwise, one turn
  for (const Span& s : spans)
    for (int i = 0; i < 2 * s.elements; ++i)
      angle.push_back(s.start + s.length * i / (2 * s.elements));
  const int around = static_cast<int>(angle.size());
  const int nr = spec.elements_through_thickness;
  FeMesh mesh;
  mesh.bars.resize(bars.size());
  // Ring node (i, j): angle i (periodic), radius R + t (j = 0) down to R (j = 2 nr).
  for (int j = 0; j <= 2 * nr; ++j) {
    const double r = radius + spec.thickness * (2 * nr - j) / (2 * nr);
    for (const double a : angle) mesh.nodes.push_back(r * Vec2{std::cos(a), std::sin(a)});
  }
  const auto ring = [&](int i, int j) { return j * around + (i % around); };
  for (int j = 0; j + 2 <= 2 * nr; j += 2)
    for (int i = 0; i < around; i += 2) {
      mesh.elements.push_back(block_element(ring, i, j));
      mesh.element_bar.push_back(-1);
    }
  mesh.fixed.assign(mesh.dofs(), 0);
  int first = 0;
  for (const Span& s : spans) {
    if (s.bar < 0) {
      for (int i = first; i < first + 2 * s.elements; i += 2)
        mesh.loaded_edges.push_back({{ring(i, 2 * nr), ring(i + 1, 2 * nr), ring(i + 2, 2 * nr)}});
    } else {
      std::vector<int> foot;
      for (int i = first; i <= first + 2 * s.elements; ++i) foot.push_back(ring(i, 2 * nr));
      add_bar(mesh, bars[static_cast<std::size_t>(s.bar)], s.bar, foot, spec.element_size);
    }
    first += 2 * s.elements;
  }
  mesh.fixed.resize(mesh.dofs(), 0);
  if (spec.clamp_outer)
    for (int i = 0; i < around; ++i) mesh.fix_node(ring(i, 0));
  return mesh;
}

FeMesh shell_mesh(const DrumGeometry& drum, const ShellMeshSpec& spec) {
  if (drum.sides() >= 3)
    throw std::invalid_argument(
        "shell_mesh: only a circular shell is meshed; a polygonal shell (drum.sides >= 3) is not");
  std::vector<FeBar> bars;
  for (const DrumGeometry::Bar& b : drum.bars()) {
    FeBar f;
    f.phi = b.phi;
    f.half_width = b.half_width;
    f.top = b.top;
    bars.push_back(f);
  }
  return shell_mesh(drum.radius(), bars, spec);
}

FeMesh grid_mesh(int nx, int ny, const std::function<Vec2(double, double)>& map) {
  if (nx < 1 || ny < 1) throw std::invalid_argument("grid_mesh: at least one element each way");
  FeMesh mesh;
  for (int j = 0; j <= 2 * ny; ++j)
    for (int i = 0; i <= 2 * nx; ++i)
      mesh.nodes.push_back(
          map(static_cast<double>(i) / (2 * nx), static_cast<double>(j) / (2 * ny)));
  const auto at = [nx](int i, int j) { return grid_node(nx, i, j); };
  for (int j = 0; j < 2 * ny; j += 2)
    for (int i = 0; i < 2 * nx; i += 2) {
      mesh.elements.push_back(block_element(at, i, j));
      mesh.element_bar.push_back(-1);
    }
  mesh.fixed.assign(mesh.dofs(), 0);
  return mesh;
}

}  // namespace dem2d
