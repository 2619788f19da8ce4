// Uniform 8-way refinement (mesher/hex_refine.h) and the `hexbite refine` command.
#include <gtest/gtest.h>
#include <vtkType.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "mesher/grid_mesher.h"
#include "mesher/hex_block.h"
#include "mesher/hex_boundary.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/hex_quality.h"
#include "mesher/hex_refine.h"
#include "mesher/surface_io.h"
#include "mesher/surface_projector.h"
#include "tests/test_util.h"

namespace hexbite {
namespace {

namespace fs = std::filesystem;
using test::run_hexbite;
using test::temp_dir;

// An nx x ny x nz block of cubes of edge h with its low corner at `origin`, vertices numbered x fastest.
HexMesh block(int nx, int ny, int nz, double h = 1.0, Vec3 origin = {0, 0, 0}) {
  return make_block_mesh(nx, ny, nz, origin, {origin[0] + h * nx, origin[1] + h * ny, origin[2] + h * nz});
}

// A closed, outward triangulated sphere of radius r: the boundary of an n^3 block, each quad split in two,
// pushed out onto the sphere.
TriSurface sphere_surface(double r, int n) {
  const HexBoundary b = extract_boundary(block(n, n, n, 2.0 / n, {-1, -1, -1}));
  TriSurface s;
  for (Vec3 p : b.surface.vertices) {
    const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    s.vertices.push_back({r * p[0] / len, r * p[1] / len, r * p[2] / len});
  }
  for (const auto& q : b.surface.quads) {
    s.triangles.push_back({q[0], q[1], q[2]});
    s.triangles.push_back({q[0], q[2], q[3]});
  }
  return s;
}

// A coarse ball: an n^3 block on [-1, 1]^3 mapped by x -> r x |x|_inf / |x|_2, boundary nodes then moved
// onto the triangulated surface exactly (closest point).
HexMesh ball_mesh(double r, int n, const SurfaceProjector& surface) {
  HexMesh mesh = block(n, n, n, 2.0 / n, {-1, -1, -1});
  for (Vec3& p : mesh.vertices) {
    const double inf = std::max({std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2])});
    const double two = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    if (two > 0)
      for (double& c : p) c *= r * inf / two;
  }
  const std::vector<char> boundary = boundary_vertex_mask(mesh);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (boundary[v]) mesh.vertices[v] = surface.closest(mesh.vertices[v]).point;
  return mesh;
}

std::set<std::array<int, 4>> sorted_quads(const HexBoundary& b) {
  std::set<std::array<int, 4>> keys;
  for (const auto& q : b.surface.quads) {
    std::array<int, 4> k;
    for (int i = 0; i < 4; ++i) k[i] = b.boundary_vertices[q[i]];
    std::sort(k.begin(), k.end());
    keys.insert(k);
  }
  return keys;
}

// The coarse vertices a fine vertex is the average of, according to the refinement map.
std::vector<int> support(const RefinementMap& map, int v) {
  const int ne = static_cast<int>(map.edges.size()), nf = static_cast<int>(map.faces.size());
  if (v < map.coarse_vertices) return {v};
  v -= map.coarse_vertices;
  if (v < ne) return {map.edges[v].begin(), map.edges[v].end()};
  v -= ne;
  if (v < nf) return {map.faces[v].begin(), map.faces[v].end()};
  return {};  // a hex centre, which never lies on the boundary
}

TEST(HexRefine, BlockCountsVolumeAndValidity) {
  const int n = 3, m = 4, k = 5;
  const HexMesh coarse = block(n, m, k, 2.5);
  RefinementMap map;
  const HexMesh fine = refine_uniform(coarse, &map);
  EXPECT_EQ(fine.hexes.size(), 8 * coarse.hexes.size());
  EXPECT_EQ(fine.vertices.size(), std::size_t((2 * n + 1) * (2 * m + 1) * (2 * k + 1)));
  EXPECT_EQ(fine.vertices.size(),
            coarse.vertices.size() + map.edges.size() + map.faces.size() + coarse.hexes.size());
  EXPECT_NEAR(hex_mesh_volume(fine), hex_mesh_volume(coarse), 1e-10 * hex_mesh_volume(coarse));
  EXPECT_EQ(extract_boundary(fine).surface.quads.size(), 4 * extract_boundary(coarse).surface.quads.size());
  const QualitySummary q = summarize_quality(fine);
  EXPECT_EQ(q.inverted, 0);
  EXPECT_NEAR(q.scaled_jacobian.min, 1.0, 1e-12);
  EXPECT_NEAR(q.condition.max, 3.0, 1e-12);
}

TEST(HexRefine, CoarseVerticesAndParentsAreKept) {
  HexMesh coarse = block(2, 3, 2);
  const HexMesh fine = refine_uniform(coarse);
  for (std::size_t v = 0; v < coarse.vertices.size(); ++v) EXPECT_EQ(fine.vertices[v], coarse.vertices[v]);
  for (std::size_t h = 0; h < coarse.hexes.size(); ++h)
    for (int c = 0; c < 8; ++c) EXPECT_EQ(fine.hexes[8 * h + c][c], coarse.hexes[h][c]);
}

TEST(HexRefine, BoundaryIsASubmeshOfTheCoarseBoundary) {
  const HexMesh coarse = block(3, 2, 4);
  RefinementMap map;
  const HexMesh fine = refine_uniform(coarse, &map);
  const std::set<std::array<int, 4>> coarse_quads = sorted_quads(extract_boundary(coarse));
  const HexBoundary fb = extract_boundary(fine);
  const int first_face = map.coarse_vertices + static_cast<int>(map.edges.size());
  for (const auto& q : fb.surface.quads) {
    // Each fine boundary quad holds exactly one coarse face centre: the coarse quad it lies in.
    std::array<int, 4> parent{-1, -1, -1, -1};
    int centres = 0;
    for (int i : q) {
      const int v = fb.boundary_vertices[i];
      if (v >= first_face && v < first_face + static_cast<int>(map.faces.size())) {
        parent = map.faces[v - first_face];
        ++centres;
      }
    }
    ASSERT_EQ(centres, 1);
    ASSERT_TRUE(coarse_quads.count(parent)) << "fine quad lies in a coarse face that is not on the boundary";
    for (int i : q) {
      const std::vector<int> s = support(map, fb.boundary_vertices[i]);
      ASSERT_FALSE(s.empty());
      for (int c : s)
        EXPECT_TRUE(std::count(parent.begin(), parent.end(), c)) << "vertex outside its coarse quad";
    }
  }
}

// child_quads gives the validation levels their patches: the children of the coarse boundary quads are
// exactly the fine boundary quads, each once, in the cyclic order (the outward orientation) of the fine
// boundary; on a refined level's map too.
TEST(HexRefine, ChildQuadsAreTheFineBoundaryQuadsWithTheirOrientation) {
  HexMesh coarse = block(3, 2, 4);
  for (int level = 0; level < 2; ++level) {
    const RefinementMap map = refinement_map(coarse);
    const HexMesh fine = refine_uniform(coarse);
    const HexBoundary cb = extract_boundary(coarse), fb = extract_boundary(fine);
    // Each fine boundary quad as its vertex ids rotated to start at the smallest: orientation kept.
    auto canonical = [](std::array<int, 4> q) {
      std::rotate(q.begin(), std::min_element(q.begin(), q.end()), q.end());
      return q;
    };
    std::set<std::array<int, 4>> fine_quads;
    for (const auto& q : fb.surface.quads)
      fine_quads.insert(canonical({fb.boundary_vertices[q[0]], fb.boundary_vertices[q[1]],
                                   fb.boundary_vertices[q[2]], fb.boundary_vertices[q[3]]}));
    std::set<std::array<int, 4>> children;
    for (const auto& q : cb.surface.quads)
      for (const auto& child : child_quads(map, {cb.boundary_vertices[q[0]], cb.boundary_vertices[q[1]],
                                                 cb.boundary_vertices[q[2]], cb.boundary_vertices[q[3]]}))
        EXPECT_TRUE(children.insert(canonical(child)).second) << "a child twice";
    EXPECT_EQ(children, fine_quads) << "level " << level;
    coarse = fine;
  }
  EXPECT_THROW(child_quads(refinement_map(coarse), {0, 1, 2, 3}), std::invalid_argument);
}

TEST(HexRefine, DistortedMeshKeepsItsVolumeExactly) {
  // The children are the parent's trilinear map restricted to its octants, so the volume is exact for any
  // hexes, not only for parallelepipeds.
  HexMesh mesh = block(4, 3, 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  for (Vec3& p : mesh.vertices)
    for (double& c : p) c += jitter(rng);
  ASSERT_EQ(summarize_quality(mesh).inverted, 0);
  const HexMesh fine = refine_uniform(mesh);
  EXPECT_NEAR(hex_mesh_volume(fine), hex_mesh_volume(mesh), 1e-12 * hex_mesh_volume(mesh));
  EXPECT_EQ(summarize_quality(fine).inverted, 0);
}

TEST(HexRefine, Deterministic) {
  HexMesh mesh = block(3, 3, 2);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  for (Vec3& p : mesh.vertices)
    for (double& c : p) c += jitter(rng);
  const HexMesh a = refine_uniform(mesh), b = refine_uniform(mesh);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.hexes, b.hexes);
}

TEST(HexRefine, WithoutSurfaceEqualsUniformRefinement) {
  const HexMesh mesh = block(2, 2, 2);
  RefineOptions options;
  options.levels = 2;
  RefineReport report;
  const HexMesh fine = refine_to_surface(mesh, nullptr, options, &report);
  const HexMesh twice = refine_uniform(refine_uniform(mesh));
  EXPECT_EQ(fine.vertices, twice.vertices);
  EXPECT_EQ(fine.hexes, twice.hexes);
  ASSERT_EQ(report.levels.size(), 2u);
  EXPECT_EQ(report.levels[1].hexes, 512);
  EXPECT_EQ(report.after.hexes, 512);
  EXPECT_FALSE(report.levels[0].optimized);
}

class BallRefine : public ::testing::Test {
 protected:
  const double radius = 10.0;
  TriSurface surface = sphere_surface(radius, 16);
  SurfaceProjector projector{surface};
  HexMesh coarse = ball_mesh(radius, 4, projector);
};

TEST_F(BallRefine, BoundaryNodesOnTheSurfaceAndNothingInverted) {
  ASSERT_EQ(summarize_quality(coarse).inverted, 0);
  for (int levels : {1, 2}) {
    RefineOptions options;
    options.levels = levels;
    RefineReport report;
    const HexMesh fine = refine_to_surface(coarse, &projector, options, &report);
    SCOPED_TRACE("levels " + std::to_string(levels));
    EXPECT_EQ(fine.hexes.size(), coarse.hexes.size() << (3 * levels));
    EXPECT_EQ(report.after.inverted, 0);
    EXPECT_EQ(summarize_quality(fine).inverted, 0);
    const std::vector<char> boundary = boundary_vertex_mask(fine);
    double worst = 0.0;
    for (std::size_t v = 0; v < fine.vertices.size(); ++v)
      if (boundary[v]) worst = std::max(worst, projector.distance(fine.vertices[v]));
    EXPECT_LT(worst, 1e-6);
    EXPECT_LT(report.levels.back().max_surface_distance, 1e-6);
    EXPECT_GT(report.levels[0].projected_nodes, 0);
    EXPECT_GT(report.levels[0].max_projection, 0.01);  // the parametric midpoints were inside the sphere
    for (std::size_t v = 0; v < coarse.vertices.size(); ++v) ASSERT_EQ(fine.vertices[v], coarse.vertices[v]);
    // Projection onto the curved surface adds volume that the chords cut off.
    EXPECT_GT(hex_mesh_volume(fine), hex_mesh_volume(coarse));
    EXPECT_NEAR(hex_mesh_volume(fine), enclosed_volume(surface), 0.02 * enclosed_volume(surface));
  }
}

TEST_F(BallRefine, Deterministic) {
  const HexMesh a = refine_to_surface(coarse, &projector, RefineOptions{});
  const HexMesh b = refine_to_surface(coarse, &projector, RefineOptions{});
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.hexes, b.hexes);
}

TEST_F(BallRefine, CommandWritesTheRefinedMesh) {
  const std::string dir = temp_dir();
  write_vtu(dir + "/coarse.vtu", coarse);
  write_surface(dir + "/ball.stl", surface);
  const auto r = run_hexbite(
      {"refine", dir + "/coarse.vtu", "--surface", dir + "/ball.stl", "-o", dir + "/fine.vtu", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["before"]["hexes"], coarse.hexes.size());
  EXPECT_EQ(j["after"]["hexes"], 8 * coarse.hexes.size());
  EXPECT_EQ(j["after"]["inverted"], 0);
  EXPECT_EQ(read_vtu(dir + "/fine.vtu").hexes.size(), 8 * coarse.hexes.size());

  const auto text = run_hexbite({"refine", dir + "/coarse.vtu", "-o", dir + "/plain.vtu", "--levels", "2"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("scaled Jacobian"), std::string::npos) << text.out;
  EXPECT_EQ(read_vtu(dir + "/plain.vtu").hexes.size(), 64 * coarse.hexes.size());
}

// A surface that is not the one the mesh was made from (another size, or the right one read in other units)
// is an input error naming the farthest boundary node, before any refinement; nothing is written. Before,
// the new boundary nodes were dragged onto it (exit 0 with a warning).
TEST_F(BallRefine, CommandRefusesASurfaceTheMeshDoesNotLieOn) {
  const std::string dir = temp_dir();
  write_vtu(dir + "/coarse.vtu", coarse);
  write_surface(dir + "/big.stl", sphere_surface(2.0 * radius, 16));
  write_surface(dir + "/ball.stl", surface);
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--surface", dir + "/big.stl"},
        std::vector<std::string>{"--surface", dir + "/ball.stl", "--units", "cm"}}) {
    std::vector<std::string> args = {"refine", dir + "/coarse.vtu", "-o", dir + "/fine.vtu"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = run_hexbite(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("'" + dir + "/coarse.vtu' does not lie on"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("give the surface the mesh was made from"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/fine.vtu"));
    EXPECT_EQ(r.err.find("Gmsh node"), std::string::npos) << r.err;
  }
  // A .msh names the farthest node by its Gmsh tag too (write_msh tags the nodes 1..n), as Gmsh shows it.
  write_msh(dir + "/coarse.msh", coarse);
  const auto r =
      run_hexbite({"refine", dir + "/coarse.msh", "--surface", dir + "/big.stl", "-o", dir + "/fine.msh"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const std::size_t at = r.err.find(" mm (node ");
  ASSERT_NE(at, std::string::npos) << r.err;
  const int node = std::stoi(r.err.substr(at + 10));
  EXPECT_NE(
      r.err.find("(node " + std::to_string(node) + ", Gmsh node " + std::to_string(node + 1) + ", at ("),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/fine.msh"));
}

// A material id (a cell array) of the input was dropped without a word: refine wrote only its quality
// arrays, and refinement.md said so. Each child hex now carries its parent's values, with the array's type;
// point arrays (no value at the new nodes) are named in a warning, and a .msh output names both.
TEST(HexRefineCommand, CellArraysGoToTheChildrenAndPointArraysAreNamed) {
  const std::string dir = temp_dir();
  const HexMesh coarse = block(2, 2, 1);
  MeshArray material{"material", 1, {}, VTK_INT}, pair{"pair", 2, {}, VTK_DOUBLE};
  for (std::size_t h = 0; h < coarse.hexes.size(); ++h) {
    material.values.push_back(double(10 + h));
    pair.values.insert(pair.values.end(), {double(h), -double(h)});
  }
  MeshArray temperature{"temperature", 1, std::vector<double>(coarse.vertices.size(), 37.0), VTK_DOUBLE};
  write_vtu(dir + "/in.vtu", coarse, {material, pair}, {temperature});
  const auto r = run_hexbite({"refine", dir + "/in.vtu", "--levels", "2", "-o", dir + "/fine.vtu", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hexbite: warning: not carried over to " + dir +
                       "/fine.vtu: point array 'temperature' (refine carries the numeric cell arrays only, "
                       "each child hex with its parent's values: the new nodes have no values)."),
            std::string::npos)
      << r.err;
  std::vector<MeshArray> cells, points;
  const HexMesh fine = read_vtu(dir + "/fine.vtu", &cells, &points);
  ASSERT_EQ(fine.hexes.size(), 64 * coarse.hexes.size());
  EXPECT_TRUE(points.empty());
  ASSERT_EQ(cells.size(), 6u);  // the four quality arrays, then the input's two
  EXPECT_EQ(cells[4].name, "material");
  EXPECT_EQ(cells[4].vtk_type, VTK_INT);
  EXPECT_EQ(cells[5].name, "pair");
  ASSERT_EQ(cells[4].values.size(), fine.hexes.size());
  ASSERT_EQ(cells[5].values.size(), 2 * fine.hexes.size());
  for (std::size_t h = 0; h < fine.hexes.size(); ++h) {
    const std::size_t parent = h / 64;  // fine hex 8 h + c is the child of h, at each level
    EXPECT_EQ(cells[4].values[h], double(10 + parent)) << h;
    EXPECT_EQ(cells[5].values[2 * h], double(parent)) << h;
    EXPECT_EQ(cells[5].values[2 * h + 1], -double(parent)) << h;
  }
  const auto msh = run_hexbite({"refine", dir + "/in.vtu", "-o", dir + "/fine.msh", "-q"});
  ASSERT_EQ(msh.exit_code, 0) << msh.err;
  EXPECT_NE(msh.err.find("not carried over to " + dir +
                         "/fine.msh: cell array 'material', cell array 'pair', point array 'temperature' "
                         "(only a .vtu output carries arrays)."),
            std::string::npos)
      << msh.err;
  // A mesh that hexbite wrote (its quality arrays only) refines without a warning.
  write_vtu(dir + "/own.vtu", coarse);
  const auto own = run_hexbite({"refine", dir + "/own.vtu", "-o", dir + "/own_fine.vtu", "-q"});
  ASSERT_EQ(own.exit_code, 0) << own.err;
  EXPECT_EQ(own.err, "");
}

TEST(HexRefineCommand, BadInput) {
  const std::string dir = temp_dir();
  // An unreadable mesh.
  test::write_file(dir + "/broken.vtu", "<VTKFile>not a mesh");
  auto r = run_hexbite({"refine", dir + "/broken.vtu", "-o", dir + "/out.vtu"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("broken.vtu"), std::string::npos) << r.err;

  // An open surface: a box without its top.
  write_vtu(dir + "/block.vtu", block(2, 2, 2));
  TriSurface open = sphere_surface(5.0, 2);
  open.triangles.resize(open.triangles.size() - 2);
  write_surface(dir + "/open.stl", open);
  r = run_hexbite({"refine", dir + "/block.vtu", "--surface", dir + "/open.stl", "-o", dir + "/out.vtu"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out.vtu"));

  // An input mesh that is already inverted: every child of an inverted hex is inverted, so it used to refine
  // everything and then fail (exit 1). It is bad input, refused before any work (exit 2), with the file, the
  // count, the hexes and where they are, and what to do; with or without a surface.
  HexMesh bad = block(2, 1, 1);
  bad.vertices[bad.hexes[1][6]] = {0.2, 0.2, 0.2};
  write_vtu(dir + "/bad.vtu", bad);
  const Vec3 c = hex_centroid(bad, 1);
  char at[96];
  std::snprintf(at, sizeof at, "hex 1 at (%.2f, %.2f, %.2f) mm", c[0], c[1], c[2]);
  for (const bool with_surface : {false, true}) {
    std::vector<std::string> args = {"refine", dir + "/bad.vtu", "-o", dir + "/out.vtu"};
    if (with_surface) args.insert(args.end(), {"--surface", dir + "/open.stl"});  // not even read
    r = run_hexbite(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("hexbite: error: '" + dir +
                         "/bad.vtu' has 1 inverted hex (a corner Jacobian <= 0), "
                         "which refinement cannot repair: " +
                         at +
                         "; nothing written: re-mesh the surface "
                         "(hexbite mesh), or find the worst hexes with hexbite quality " +
                         dir + "/bad.vtu --worst 1"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(fs::exists(dir + "/out.vtu"));
  }
}

}  // namespace
}  // namespace hexbite
