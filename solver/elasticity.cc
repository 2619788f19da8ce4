// The linear elasticity solver: one class whose methods follow the algorithm, in the manner of deal.II's
// step-8 (vector-valued elasticity), step-40 (distributed meshes and Trilinos linear algebra) and step-42
// (algebraic multigrid for elasticity).
//
// The hex mesh arrives as plain arrays and becomes the coarse mesh of a parallel::distributed::Triangulation,
// which is never refined: every deal.II cell is one hex of the input and cell->index() is its hex index. The
// same code runs on one rank without mpirun and on N ranks under mpirun; every rank keeps the whole coarse
// mesh (p4est's design) and owns a share of the cells and degrees of freedom.
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <Teuchos_ParameterList.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>
#include <unordered_map>

#include "common/error.h"
#include "solver/elasticity.h"

namespace hexbite {
namespace {

using namespace dealii;

constexpr int dim = 3;

// VTK node i of a hexahedron is deal.II vertex kVtkToDealii[i] (deal.II numbers vertices lexicographically).
constexpr unsigned int kVtkToDealii[8] = {0, 1, 3, 2, 4, 5, 7, 6};

Point<dim> to_point(const Vec3& v) {
  return Point<dim>(v[0], v[1], v[2]);
}
Vec3 to_vec3(const Point<dim>& p) {
  return {p[0], p[1], p[2]};
}
Vec3 to_vec3(const Tensor<1, dim>& t) {
  return {t[0], t[1], t[2]};
}

double von_mises(const SymmetricTensor<2, dim>& stress) {
  const SymmetricTensor<2, dim> s = deviator(stress);
  return std::sqrt(1.5 * scalar_product(s, s));
}

Stress6 to_stress6(const SymmetricTensor<2, dim>& s) {
  return {s[0][0], s[1][1], s[2][2], s[0][1], s[1][2], s[0][2]};
}

// The Lamé parameters of one hex's material.
struct Lame {
  double lambda;
  double mu;
};

Lame lame(const Material& m) {
  const double E = m.youngs_modulus, nu = m.poisson_ratio;
  return {E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))};
}

// Which patch a boundary face belongs to: a load (index into problem.loads) or a support.
struct PatchRef {
  bool is_load;
  unsigned int index;
};

class ElasticitySolver {
 public:
  explicit ElasticitySolver(const ElasticityProblem& problem);
  ElasticitySolution run();

 private:
  void make_grid();
  void identify_patch_faces();
  void setup_system();
  void make_constraints();
  void assemble_system();
  void solve();
  void compute_reactions();
  void compute_stresses();
  void compute_vertex_displacements();
  void evaluate_probes();
  void compute_errors();

  // Helpers shared by the assembly and the residual computation, so that the reactions come from exactly
  // the operator that was solved.
  const Material& material_of(unsigned int hex) const;
  void cell_stiffness(const FEValues<dim>& fe_values, const Lame& l, FullMatrix<double>& cell_matrix) const;
  void cell_loads(const typename DoFHandler<dim>::active_cell_iterator& cell, FEValues<dim>& fe_values,
                  FEFaceValues<dim>& fe_face_values, FullMatrix<double>& cell_matrix,
                  Vector<double>& cell_rhs) const;
  const std::vector<PatchRef>* patches_of(unsigned int hex, unsigned int face) const;

  const ElasticityProblem& problem;
  const HexMesh& mesh;
  MPI_Comm mpi_communicator;

  parallel::distributed::Triangulation<dim> triangulation;
  const MappingQ1<dim> mapping;
  const FESystem<dim> fe;
  DoFHandler<dim> dof_handler;
  const QGauss<dim> quadrature;
  const QGauss<dim - 1> face_quadrature;

  IndexSet locally_owned_dofs;
  IndexSet locally_relevant_dofs;
  AffineConstraints<double> constraints;
  TrilinosWrappers::SparseMatrix system_matrix;
  TrilinosWrappers::MPI::Vector system_rhs;
  TrilinosWrappers::MPI::Vector locally_relevant_solution;

  // The patches of each boundary face that belongs to at least one, keyed by 6 * hex + deal.II face number.
  std::unordered_map<std::uint64_t, std::vector<PatchRef>> face_patches;
  std::vector<double> load_area;  // mm^2 per traction patch
  // Owned constrained DoF -> (support index, component), for the reaction forces.
  std::unordered_map<types::global_dof_index, std::pair<unsigned int, unsigned int>> fixed_dof_support;

  ElasticitySolution solution;
};

ElasticitySolver::ElasticitySolver(const ElasticityProblem& problem)
    : problem(problem),
      mesh(*problem.mesh),
      mpi_communicator(problem.distribute_over_all_ranks ? MPI_COMM_WORLD : MPI_COMM_SELF),
      triangulation(mpi_communicator),
      fe(FE_Q<dim>(problem.degree), dim),
      dof_handler(triangulation),
      quadrature(problem.degree + 1),
      face_quadrature(problem.degree + 1) {}

const Material& ElasticitySolver::material_of(unsigned int hex) const {
  return problem.hex_material.empty() ? problem.material : problem.hex_material[hex];
}

const std::vector<PatchRef>* ElasticitySolver::patches_of(unsigned int hex, unsigned int face) const {
  const auto it = face_patches.find(6 * std::uint64_t(hex) + face);
  return it == face_patches.end() ? nullptr : &it->second;
}

// @sect3{Checking the input}
//
// Everything that would otherwise surface as a deal.II assertion deep inside the library (or, worse, as a
// singular matrix) is checked here first, with a message that names the offending item.
void validate_problem(const ElasticityProblem& problem) {
  const HexMesh& mesh = *problem.mesh;
  auto check_material = [](const Material& m, const std::string& where) {
    if (!(m.youngs_modulus > 0.0))
      throw InputError(where + ": Young's modulus must be positive (got " + std::to_string(m.youngs_modulus) +
                       " MPa)");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
      throw InputError(where + ": Poisson's ratio must lie in (-1, 0.5) (got " +
                       std::to_string(m.poisson_ratio) + ")");
  };
  if (mesh.hexes.empty()) throw InputError("elasticity: the hex mesh is empty");
  if (problem.degree != 1 && problem.degree != 2)
    throw InputError("elasticity: element degree must be 1 or 2 (got " + std::to_string(problem.degree) +
                     ")");
  check_material(problem.material, "material");
  if (!problem.hex_material.empty()) {
    if (problem.hex_material.size() != mesh.hexes.size())
      throw InputError("elasticity: per-hex materials given for " +
                       std::to_string(problem.hex_material.size()) + " hexes, but the mesh has " +
                       std::to_string(mesh.hexes.size()));
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
      check_material(problem.hex_material[h], "material of hex " + std::to_string(h));
  }
  const int n_vertices = static_cast<int>(mesh.vertices.size());
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (int v : mesh.hexes[h])
      if (v < 0 || v >= n_vertices)
        throw InputError("elasticity: hex " + std::to_string(h) + " refers to vertex " + std::to_string(v) +
                         ", but the mesh has " + std::to_string(n_vertices) + " vertices");
  if (problem.supports.empty())
    throw InputError("elasticity: no support given; without one the bone floats freely (singular problem)");
  for (const auto& s : problem.supports) {
    if (s.faces.empty()) throw InputError("support '" + s.name + "' selects no boundary faces");
    if (!(s.spring_stiffness >= 0.0))
      throw InputError("support '" + s.name + "': spring stiffness must not be negative");
    if (!s.components[0] && !s.components[1] && !s.components[2])
      throw InputError("support '" + s.name + "' acts on none of the components x, y, z");
  }
  for (const auto& l : problem.loads)
    if (l.faces.empty()) throw InputError("load '" + l.name + "' selects no boundary faces");
}

// @sect3{The mesh}
//
// The plain arrays become deal.II's CellData. Cells are oriented consistently where deal.II's reordering
// succeeds (it reorders vertices within cells, never the cells themselves), and inverted cells are flipped,
// so that mesh files in either handedness work. Cell indices stay the hex indices, which we check.
void ElasticitySolver::make_grid() {
  std::vector<Point<dim>> vertices(mesh.vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) vertices[i] = to_point(mesh.vertices[i]);
  std::vector<CellData<dim>> cells(mesh.hexes.size());
  for (std::size_t h = 0; h < cells.size(); ++h) {
    for (unsigned int i = 0; i < 8; ++i) cells[h].vertices[kVtkToDealii[i]] = mesh.hexes[h][i];
    cells[h].material_id = 0;
  }
  GridTools::invert_all_negative_measure_cells(vertices, cells);
  GridTools::consistently_order_cells(cells);
  triangulation.create_triangulation(vertices, cells, SubCellData());

  for (const auto& cell : triangulation.active_cell_iterators()) {
    const auto& hex = mesh.hexes[cell->index()];
    if (std::find(hex.begin(), hex.end(), static_cast<int>(cell->vertex_index(0))) == hex.end())
      throw RunError("elasticity: deal.II reordered the cells of the mesh; cell " +
                     std::to_string(cell->index()) + " is not hex " + std::to_string(cell->index()));
  }
}

// @sect3{Loads and supports on boundary faces}
//
// Patches list faces as four vertex ids. We find every boundary face of the mesh among them, remember which
// patches it belongs to, and compute the area of each traction patch (so that the uniform traction F / area
// integrates to F). Every rank holds the whole coarse mesh, so this needs no communication, except the
// areas, which we integrate over locally owned cells only.
void ElasticitySolver::identify_patch_faces() {
  std::map<BoundaryQuad, std::vector<PatchRef>> wanted;
  std::vector<std::vector<BoundaryQuad>> patch_faces;
  auto add_patch = [&](const std::vector<BoundaryQuad>& faces, PatchRef ref) {
    for (BoundaryQuad q : faces) {
      std::sort(q.begin(), q.end());
      auto& refs = wanted[q];
      // A face listed twice in one patch counts once.
      if (refs.empty() || refs.back().is_load != ref.is_load || refs.back().index != ref.index)
        refs.push_back(ref);
    }
  };
  for (unsigned int i = 0; i < problem.loads.size(); ++i) add_patch(problem.loads[i].faces, {true, i});
  for (unsigned int i = 0; i < problem.supports.size(); ++i) add_patch(problem.supports[i].faces, {false, i});

  std::map<BoundaryQuad, bool> found;
  for (const auto& cell : triangulation.active_cell_iterators())
    for (const unsigned int f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      BoundaryQuad key;
      for (unsigned int v = 0; v < 4; ++v) key[v] = cell->face(f)->vertex_index(v);
      std::sort(key.begin(), key.end());
      const auto it = wanted.find(key);
      if (it == wanted.end()) continue;
      face_patches[6 * std::uint64_t(cell->index()) + f] = it->second;
      found[key] = true;
    }

  auto check_patch = [&](const std::vector<BoundaryQuad>& faces, const std::string& what) {
    for (BoundaryQuad q : faces) {
      BoundaryQuad key = q;
      std::sort(key.begin(), key.end());
      if (!found.count(key)) {
        std::ostringstream msg;
        msg << what << ": the quad (" << q[0] << ", " << q[1] << ", " << q[2] << ", " << q[3]
            << ") is not a boundary face of the hex mesh";
        throw InputError(msg.str());
      }
    }
  };
  for (const auto& l : problem.loads) check_patch(l.faces, "load '" + l.name + "'");
  for (const auto& s : problem.supports) check_patch(s.faces, "support '" + s.name + "'");

  load_area.assign(problem.loads.size(), 0.0);
  FEFaceValues<dim> fe_face_values(mapping, fe, face_quadrature, update_JxW_values);
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (const unsigned int f : cell->face_indices()) {
      const auto* refs = patches_of(cell->index(), f);
      if (!refs) continue;
      fe_face_values.reinit(cell, f);
      double area = 0.0;
      for (unsigned int q = 0; q < face_quadrature.size(); ++q) area += fe_face_values.JxW(q);
      for (const PatchRef& r : *refs)
        if (r.is_load) load_area[r.index] += area;
    }
  }
  Utilities::MPI::sum(load_area, mpi_communicator, load_area);
}

// @sect3{Degrees of freedom and the linear system}
//
// As in step-40: distribute the DoFs, determine which ones this rank owns and which it can see, build the
// constraints, and a sparsity pattern distributed so that each rank stores the rows it owns. For a vector
// FE_Q, deal.II numbers the three components of one node consecutively, which is the interleaved layout ML
// expects when told that the matrix has three PDE equations.
void ElasticitySolver::setup_system() {
  dof_handler.distribute_dofs(fe);
  locally_owned_dofs = dof_handler.locally_owned_dofs();
  DoFTools::extract_locally_relevant_dofs(dof_handler, locally_relevant_dofs);
  solution.dofs = static_cast<long long>(dof_handler.n_dofs());

  make_constraints();

  DynamicSparsityPattern dsp(locally_relevant_dofs);
  DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
  SparsityTools::distribute_sparsity_pattern(dsp, locally_owned_dofs, mpi_communicator,
                                             locally_relevant_dofs);
  system_matrix.reinit(locally_owned_dofs, locally_owned_dofs, dsp, mpi_communicator);
  system_rhs.reinit(locally_owned_dofs, mpi_communicator);
  locally_relevant_solution.reinit(locally_owned_dofs, locally_relevant_dofs, mpi_communicator);
}

// Fixed supports become constraints u_c = g_c(x) on every DoF of the patch's faces (vertex, edge and face
// DoFs for Q2), in the patch's components only. The value of a DoF is the prescribed displacement at its
// support point (zero for the hard nut). A DoF on several fixed patches belongs to the first one; we
// remember that owner for the reaction forces.
void ElasticitySolver::make_constraints() {
  constraints.clear();
  constraints.reinit(locally_relevant_dofs);
  const std::vector<Point<dim>>& unit_support_points = fe.get_unit_support_points();
  std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (cell->is_artificial()) continue;
    bool has_fixed_face = false;
    for (const unsigned int f : cell->face_indices())
      if (const auto* refs = patches_of(cell->index(), f))
        for (const PatchRef& r : *refs)
          has_fixed_face |= !r.is_load && problem.supports[r.index].spring_stiffness == 0.0;
    if (!has_fixed_face) continue;

    cell->get_dof_indices(dof_indices);
    for (const unsigned int f : cell->face_indices()) {
      const auto* refs = patches_of(cell->index(), f);
      if (!refs) continue;
      for (const PatchRef& r : *refs) {
        const SupportPatch& support = problem.supports[r.index];
        if (r.is_load || support.spring_stiffness > 0.0) continue;
        for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i) {
          const unsigned int c = fe.system_to_component_index(i).first;
          if (!support.components[c] || !fe.has_support_on_face(i, f)) continue;
          const types::global_dof_index dof = dof_indices[i];
          if (constraints.is_constrained(dof)) continue;
          double value = 0.0;
          if (support.displacement) {
            const Point<dim> x = mapping.transform_unit_to_real_cell(cell, unit_support_points[i]);
            value = support.displacement(to_vec3(x))[c];
          }
          constraints.add_line(dof);
          constraints.set_inhomogeneity(dof, value);
          if (locally_owned_dofs.is_element(dof)) fixed_dof_support[dof] = {r.index, c};
        }
      }
    }
  }
  constraints.close();
}

// @sect3{Assembly}
//
// The element stiffness of isotropic elasticity in the component form of step-8: every shape function of
// the vector FE_Q is nonzero in exactly one component, so
//   K_ij = lambda d_ci N_i d_cj N_j + mu d_cj N_i d_ci N_j + [c_i == c_j] mu grad N_i . grad N_j.
// The matrix is symmetric, so we compute its lower triangle and mirror it.
void ElasticitySolver::cell_stiffness(const FEValues<dim>& fe_values, const Lame& l,
                                      FullMatrix<double>& cell_matrix) const {
  const unsigned int n = fe.n_dofs_per_cell();
  cell_matrix = 0;
  for (unsigned int q = 0; q < fe_values.n_quadrature_points; ++q) {
    const double JxW = fe_values.JxW(q);
    for (unsigned int i = 0; i < n; ++i) {
      const unsigned int ci = fe.system_to_component_index(i).first;
      const Tensor<1, dim>& gi = fe_values.shape_grad(i, q);
      for (unsigned int j = 0; j <= i; ++j) {
        const unsigned int cj = fe.system_to_component_index(j).first;
        const Tensor<1, dim>& gj = fe_values.shape_grad(j, q);
        double value = l.lambda * gi[ci] * gj[cj] + l.mu * gi[cj] * gj[ci];
        if (ci == cj) value += l.mu * (gi * gj);
        cell_matrix(i, j) += value * JxW;
      }
    }
  }
  for (unsigned int i = 0; i < n; ++i)
    for (unsigned int j = i + 1; j < n; ++j) cell_matrix(i, j) = cell_matrix(j, i);
}

// The rest of a cell's contribution: the spring supports' boundary mass term k u on their faces (added to
// the cell matrix), the body force, and the uniform tractions F / area of the load patches.
void ElasticitySolver::cell_loads(const typename DoFHandler<dim>::active_cell_iterator& cell,
                                  FEValues<dim>& fe_values, FEFaceValues<dim>& fe_face_values,
                                  FullMatrix<double>& cell_matrix, Vector<double>& cell_rhs) const {
  const unsigned int n = fe.n_dofs_per_cell();
  cell_rhs = 0;
  if (problem.body_force)
    for (unsigned int q = 0; q < fe_values.n_quadrature_points; ++q) {
      const Vec3 b = problem.body_force(to_vec3(fe_values.quadrature_point(q)));
      for (unsigned int i = 0; i < n; ++i) {
        const unsigned int ci = fe.system_to_component_index(i).first;
        cell_rhs(i) += fe_values.shape_value(i, q) * b[ci] * fe_values.JxW(q);
      }
    }

  for (const unsigned int f : cell->face_indices()) {
    const auto* refs = patches_of(cell->index(), f);
    if (!refs) continue;
    fe_face_values.reinit(cell, f);
    for (const PatchRef& r : *refs) {
      if (r.is_load) {
        const TractionPatch& load = problem.loads[r.index];
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
          for (unsigned int i = 0; i < n; ++i) {
            const unsigned int ci = fe.system_to_component_index(i).first;
            cell_rhs(i) += fe_face_values.shape_value(i, q) * load.force[ci] / load_area[r.index] *
                           fe_face_values.JxW(q);
          }
      } else if (problem.supports[r.index].spring_stiffness > 0.0) {
        const SupportPatch& spring = problem.supports[r.index];
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
          for (unsigned int i = 0; i < n; ++i) {
            const unsigned int ci = fe.system_to_component_index(i).first;
            if (!spring.components[ci]) continue;
            for (unsigned int j = 0; j < n; ++j)
              if (fe.system_to_component_index(j).first == ci)
                cell_matrix(i, j) += spring.spring_stiffness * fe_face_values.shape_value(i, q) *
                                     fe_face_values.shape_value(j, q) * fe_face_values.JxW(q);
          }
      }
    }
  }
}

void ElasticitySolver::assemble_system() {
  FEValues<dim> fe_values(mapping, fe, quadrature,
                          update_values | update_gradients | update_quadrature_points | update_JxW_values);
  FEFaceValues<dim> fe_face_values(mapping, fe, face_quadrature, update_values | update_JxW_values);
  FullMatrix<double> cell_matrix(fe.n_dofs_per_cell(), fe.n_dofs_per_cell());
  Vector<double> cell_rhs(fe.n_dofs_per_cell());
  std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());

  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fe_values.reinit(cell);
    cell_stiffness(fe_values, lame(material_of(cell->index())), cell_matrix);
    cell_loads(cell, fe_values, fe_face_values, cell_matrix, cell_rhs);
    cell->get_dof_indices(dof_indices);
    constraints.distribute_local_to_global(cell_matrix, cell_rhs, dof_indices, system_matrix, system_rhs);
  }
  system_matrix.compress(VectorOperation::add);
  system_rhs.compress(VectorOperation::add);
}

// @sect3{Solving}
//
// The default is CG preconditioned with Trilinos ML smoothed aggregation. Out of the box ML treats the
// matrix as a scalar problem with a constant null space, which for elasticity aggregates x, y and z DoFs
// without regard for nodes and ignores rotations: CG then needs several times more iterations, growing
// with the mesh. We therefore tell ML that there are three PDE equations per node and hand it the six
// rigid-body modes (deal.II 9.4 cannot compute them: DoFTools::extract_rigid_body_modes arrived in 9.7).
// The aggregation threshold 0 keeps all matrix couplings for aggregation, which suits the strongly coupled
// vector problem on distorted hexes. The mode array must stay alive until initialize() has returned.
void ElasticitySolver::solve() {
  TrilinosWrappers::MPI::Vector distributed_solution(locally_owned_dofs, mpi_communicator);
  if (system_rhs.l2_norm() == 0.0) {
    // No load, no prescribed displacement: the answer is zero, and CG would divide by a zero residual.
    solution.iterations = 0;
  } else if (problem.solver.linear_solver == LinearSolver::kDirect) {
    SolverControl control(1, 0);
    TrilinosWrappers::SolverDirect direct(
        control, TrilinosWrappers::SolverDirect::AdditionalData(false, "Amesos_Mumps"));
    try {
      direct.solve(system_matrix, distributed_solution, system_rhs);
    } catch (const ExceptionBase&) {
      // deal.II's text is a source line and a stack trace; Amesos has printed MUMPS's codes above it.
      throw DirectSolverError(
          "elasticity: the direct solver (MUMPS) failed; its lines above give its code (INFOG(1) = -13: it "
          "could not allocate its workspace, as under a memory or address-space limit, ulimit -v)");
    }
    solution.iterations = 0;
  } else {
    // The rigid-body modes, mode after mode, over the locally owned rows in the matrix's row order
    // (locally owned DoFs form one contiguous range in that order). Rotations are about the mesh centroid
    // so that the modes have comparable magnitude.
    const unsigned int n_local = locally_owned_dofs.n_elements();
    std::vector<double> modes(6 * std::size_t(n_local), 0.0);
    Point<dim> centroid;
    for (const Vec3& v : mesh.vertices) centroid += to_point(v);
    centroid /= static_cast<double>(mesh.vertices.size());

    const std::vector<Point<dim>>& unit_support_points = fe.get_unit_support_points();
    std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
    for (const auto& cell : dof_handler.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      cell->get_dof_indices(dof_indices);
      for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i) {
        if (!locally_owned_dofs.is_element(dof_indices[i])) continue;
        const std::size_t row = locally_owned_dofs.index_within_set(dof_indices[i]);
        const unsigned int c = fe.system_to_component_index(i).first;
        const Tensor<1, dim> x = mapping.transform_unit_to_real_cell(cell, unit_support_points[i]) - centroid;
        // Translation in direction c, then the rotations about x, y and z: u = e_axis cross x, component c.
        modes[c * n_local + row] = 1.0;
        const double rot[3][3] = {{0.0, -x[2], x[1]}, {x[2], 0.0, -x[0]}, {-x[1], x[0], 0.0}};
        for (unsigned int axis = 0; axis < 3; ++axis) modes[(3 + axis) * n_local + row] = rot[axis][c];
      }
    }

    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic = true;
    amg_data.higher_order_elements = problem.degree > 1;
    amg_data.aggregation_threshold = 0.0;
    amg_data.smoother_sweeps = 2;
    amg_data.output_details = false;
    Teuchos::ParameterList ml_parameters;
    std::unique_ptr<Epetra_MultiVector> constant_modes;
    amg_data.set_parameters(ml_parameters, constant_modes, system_matrix);
    ml_parameters.set("PDE equations", 3);
    ml_parameters.set("aggregation: threshold", 0.0);
    ml_parameters.set("null space: type", "pre-computed");
    ml_parameters.set("null space: dimension", 6);
    ml_parameters.set("null space: vectors", modes.data());
    ml_parameters.set("ML output", 0);

    TrilinosWrappers::PreconditionAMG preconditioner;
    preconditioner.initialize(system_matrix, ml_parameters);

    SolverControl control(problem.solver.max_iterations,
                          problem.solver.relative_tolerance * system_rhs.l2_norm());
    SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
    try {
      cg.solve(system_matrix, distributed_solution, system_rhs, preconditioner);
    } catch (const SolverControl::NoConvergence& e) {
      std::ostringstream msg;
      msg << "elasticity: CG did not converge in " << e.last_step << " iterations (residual "
          << e.last_residual << ", wanted " << control.tolerance()
          << "); the supports may not hold the bone against all rigid motions, or raise max_iterations";
      throw RunError(msg.str());
    }
    solution.iterations = static_cast<int>(control.last_step());
  }
  constraints.distribute(distributed_solution);
  locally_relevant_solution = distributed_solution;
  if (!std::isfinite(distributed_solution.l2_norm()))
    throw RunError(
        "elasticity: the solution is not finite; the supports may not hold the bone against all "
        "rigid motions");
}

// @sect3{Reaction forces and equilibrium}
//
// The reaction of a fixed support is what the constraint had to supply: the residual r = K u - f of the
// unconstrained operator (the spring terms included), summed over the support's constrained DoFs. We
// assemble r cell by cell from the same element routines as the system, so it measures exactly the
// equations that were solved. A spring's reaction is its traction -k u integrated over its faces. With the
// loads, these must sum to zero up to the solver tolerance: the residual left at the free DoFs is exactly
// what breaks the balance, which is what the equilibrium check measures.
void ElasticitySolver::compute_reactions() {
  // Writable ghost entries: each rank adds its cells' contributions to DoFs owned by neighbours too.
  TrilinosWrappers::MPI::Vector residual;
  residual.reinit(locally_owned_dofs, locally_relevant_dofs, mpi_communicator, true);
  FEValues<dim> fe_values(mapping, fe, quadrature,
                          update_values | update_gradients | update_quadrature_points | update_JxW_values);
  FEFaceValues<dim> fe_face_values(mapping, fe, face_quadrature,
                                   update_values | update_JxW_values | update_quadrature_points);
  const unsigned int n = fe.n_dofs_per_cell();
  FullMatrix<double> cell_matrix(n, n);
  Vector<double> cell_rhs(n), cell_u(n), cell_r(n);
  std::vector<types::global_dof_index> dof_indices(n);
  std::vector<Vector<double>> face_u(face_quadrature.size(), Vector<double>(dim));

  std::vector<double> forces(3 * problem.supports.size(), 0.0);
  Vec3 body_force_total{0.0, 0.0, 0.0};
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fe_values.reinit(cell);
    cell_stiffness(fe_values, lame(material_of(cell->index())), cell_matrix);
    cell_loads(cell, fe_values, fe_face_values, cell_matrix, cell_rhs);
    cell->get_dof_indices(dof_indices);
    cell->get_dof_values(locally_relevant_solution, cell_u);
    cell_matrix.vmult(cell_r, cell_u);
    cell_r -= cell_rhs;
    residual.add(dof_indices, cell_r);

    if (problem.body_force)
      for (unsigned int q = 0; q < quadrature.size(); ++q) {
        const Vec3 b = problem.body_force(to_vec3(fe_values.quadrature_point(q)));
        for (unsigned int c = 0; c < dim; ++c) body_force_total[c] += b[c] * fe_values.JxW(q);
      }

    for (const unsigned int f : cell->face_indices()) {
      const auto* refs = patches_of(cell->index(), f);
      if (!refs) continue;
      for (const PatchRef& r : *refs) {
        if (r.is_load || problem.supports[r.index].spring_stiffness == 0.0) continue;
        const SupportPatch& spring = problem.supports[r.index];
        fe_face_values.reinit(cell, f);
        fe_face_values.get_function_values(locally_relevant_solution, face_u);
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
          for (unsigned int c = 0; c < dim; ++c)
            if (spring.components[c])
              forces[3 * r.index + c] -= spring.spring_stiffness * face_u[q][c] * fe_face_values.JxW(q);
      }
    }
  }
  residual.compress(VectorOperation::add);
  for (const auto& [dof, owner] : fixed_dof_support) forces[3 * owner.first + owner.second] += residual[dof];
  Utilities::MPI::sum(forces, mpi_communicator, forces);
  for (unsigned int c = 0; c < dim; ++c)
    body_force_total[c] = Utilities::MPI::sum(body_force_total[c], mpi_communicator);

  solution.applied_force = body_force_total;
  for (const auto& l : problem.loads)
    for (unsigned int c = 0; c < dim; ++c) solution.applied_force[c] += l.force[c];

  Tensor<1, dim> total = to_point(solution.applied_force), bite;
  double reaction_magnitudes = 0.0;
  for (unsigned int s = 0; s < problem.supports.size(); ++s) {
    SupportReaction reaction;
    reaction.name = problem.supports[s].name;
    reaction.is_bite = problem.supports[s].is_bite;
    Tensor<1, dim> f;
    for (unsigned int c = 0; c < dim; ++c) f[c] = forces[3 * s + c];
    reaction.force = to_vec3(f);
    reaction.magnitude = f.norm();
    reaction_magnitudes += reaction.magnitude;
    total += f;
    if (reaction.is_bite) bite += f;
    solution.reactions.push_back(reaction);
  }
  solution.bite_force = bite.norm();
  // Issue 5's definition: |applied + all reactions| / |applied|, |applied| the norm of the net applied
  // force. Loads that cancel leave no such scale (|applied| 0, or round-off below 1e-12 of the loads): the
  // residual is then relative to the larger of the sum of the reaction magnitudes and the largest single
  // load (a patch's force or the body force), and 0 when there is nothing at all.
  double fallback = std::max(reaction_magnitudes, to_point(body_force_total).norm());
  for (const auto& l : problem.loads) fallback = std::max(fallback, to_point(l.force).norm());
  const double applied = to_point(solution.applied_force).norm();
  const double scale = applied > 1e-12 * fallback ? applied : fallback;
  solution.equilibrium_residual = scale > 0.0 ? total.norm() / scale : 0.0;
}

// @sect3{Displacements at the mesh vertices}
//
// Every vertex carries DoFs (for Q1 and Q2 alike). The rank that owns a vertex's DoFs writes them, all
// others write zero, and a sum over the ranks gives every rank the complete field.
void ElasticitySolver::compute_vertex_displacements() {
  std::vector<double> u(3 * mesh.vertices.size(), 0.0);
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (const unsigned int v : cell->vertex_indices())
      for (unsigned int c = 0; c < dim; ++c) {
        const types::global_dof_index dof = cell->vertex_dof_index(v, c);
        if (locally_owned_dofs.is_element(dof))
          u[3 * cell->vertex_index(v) + c] = locally_relevant_solution[dof];
      }
  }
  Utilities::MPI::sum(u, mpi_communicator, u);
  solution.vertex_displacement.resize(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    solution.vertex_displacement[i] = {u[3 * i], u[3 * i + 1], u[3 * i + 2]};
    const double magnitude =
        std::sqrt(u[3 * i] * u[3 * i] + u[3 * i + 1] * u[3 * i + 1] + u[3 * i + 2] * u[3 * i + 2]);
    if (magnitude > solution.max_displacement) {
      solution.max_displacement = magnitude;
      solution.max_displacement_at = mesh.vertices[i];
    }
  }
}

// @sect3{Stresses}
//
// sigma = lambda tr(eps) I + 2 mu eps at the quadrature points gives the per-hex averages, the maxima of
// von Mises and the strain energy; the same formula at the eight corners of each hex, averaged over the
// hexes around a vertex, gives a smooth nodal field for plots. Per-hex arrays are filled by the owning rank
// and summed over the ranks.
void ElasticitySolver::compute_stresses() {
  const std::size_t n_hexes = mesh.hexes.size();
  std::vector<double> hex_stress(6 * n_hexes, 0.0), hex_vm(n_hexes, 0.0), hex_vm_max(n_hexes, 0.0);
  std::vector<double> vertex_stress(6 * mesh.vertices.size(), 0.0), vertex_count(mesh.vertices.size(), 0.0);
  double energy = 0.0;
  std::array<double, 4> vm_max{-1.0, 0.0, 0.0, 0.0};  // value, location

  const FEValuesExtractors::Vector displacements(0);
  FEValues<dim> fe_values(mapping, fe, quadrature,
                          update_gradients | update_quadrature_points | update_JxW_values);
  std::vector<Point<dim>> corners;
  for (const unsigned int v : GeometryInfo<dim>::vertex_indices())
    corners.push_back(GeometryInfo<dim>::unit_cell_vertex(v));
  FEValues<dim> fe_corner_values(mapping, fe, Quadrature<dim>(corners), update_gradients);
  std::vector<SymmetricTensor<2, dim>> strains(quadrature.size()), corner_strains(corners.size());

  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    const unsigned int h = cell->index();
    const Lame l = lame(material_of(h));
    auto stress_of = [&l](const SymmetricTensor<2, dim>& eps) {
      return l.lambda * trace(eps) * unit_symmetric_tensor<dim>() + 2.0 * l.mu * eps;
    };
    fe_values.reinit(cell);
    fe_values[displacements].get_function_symmetric_gradients(locally_relevant_solution, strains);
    SymmetricTensor<2, dim> stress_integral;
    double vm_integral = 0.0, volume = 0.0;
    for (unsigned int q = 0; q < quadrature.size(); ++q) {
      const SymmetricTensor<2, dim> sigma = stress_of(strains[q]);
      const double vm = von_mises(sigma), JxW = fe_values.JxW(q);
      stress_integral += sigma * JxW;
      vm_integral += vm * JxW;
      volume += JxW;
      energy += 0.5 * scalar_product(sigma, strains[q]) * JxW;
      hex_vm_max[h] = std::max(hex_vm_max[h], vm);
      if (vm > vm_max[0])
        vm_max = {vm, fe_values.quadrature_point(q)[0], fe_values.quadrature_point(q)[1],
                  fe_values.quadrature_point(q)[2]};
    }
    const Stress6 average = to_stress6(stress_integral / volume);
    std::copy(average.begin(), average.end(), hex_stress.begin() + 6 * h);
    hex_vm[h] = vm_integral / volume;

    fe_corner_values.reinit(cell);
    fe_corner_values[displacements].get_function_symmetric_gradients(locally_relevant_solution,
                                                                     corner_strains);
    for (const unsigned int v : cell->vertex_indices()) {
      const Stress6 s = to_stress6(stress_of(corner_strains[v]));
      const unsigned int vertex = cell->vertex_index(v);
      for (unsigned int k = 0; k < 6; ++k) vertex_stress[6 * vertex + k] += s[k];
      vertex_count[vertex] += 1.0;
    }
  }
  Utilities::MPI::sum(hex_stress, mpi_communicator, hex_stress);
  Utilities::MPI::sum(hex_vm, mpi_communicator, hex_vm);
  Utilities::MPI::sum(hex_vm_max, mpi_communicator, hex_vm_max);
  Utilities::MPI::sum(vertex_stress, mpi_communicator, vertex_stress);
  Utilities::MPI::sum(vertex_count, mpi_communicator, vertex_count);
  solution.strain_energy = Utilities::MPI::sum(energy, mpi_communicator);
  // The largest von Mises value over all ranks, and where it is (the lowest rank wins ties).
  for (const auto& candidate : Utilities::MPI::all_gather(mpi_communicator, vm_max))
    if (candidate[0] > solution.von_mises_max) {
      solution.von_mises_max = candidate[0];
      solution.von_mises_max_at = {candidate[1], candidate[2], candidate[3]};
    }

  solution.hex_stress.resize(n_hexes);
  solution.hex_principal_stress.resize(n_hexes);
  for (std::size_t h = 0; h < n_hexes; ++h) {
    Stress6& s = solution.hex_stress[h];
    std::copy(hex_stress.begin() + 6 * h, hex_stress.begin() + 6 * h + 6, s.begin());
    SymmetricTensor<2, dim> sigma;
    sigma[0][0] = s[0], sigma[1][1] = s[1], sigma[2][2] = s[2], sigma[0][1] = s[3], sigma[1][2] = s[4],
    sigma[0][2] = s[5];
    const std::array<double, 3> principal = eigenvalues(sigma);
    solution.hex_principal_stress[h] = {principal[0], principal[1], principal[2]};
  }
  solution.hex_von_mises = hex_vm;
  solution.hex_von_mises_max = hex_vm_max;

  std::vector<double> sorted = hex_vm;
  const std::size_t rank99 = static_cast<std::size_t>(std::ceil(0.99 * n_hexes)) - 1;
  std::nth_element(sorted.begin(), sorted.begin() + rank99, sorted.end());
  solution.von_mises_p99 = sorted[rank99];

  solution.vertex_von_mises.assign(mesh.vertices.size(), 0.0);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (vertex_count[v] == 0.0) continue;
    SymmetricTensor<2, dim> sigma;
    const double* s = &vertex_stress[6 * v];
    sigma[0][0] = s[0], sigma[1][1] = s[1], sigma[2][2] = s[2], sigma[0][1] = s[3], sigma[1][2] = s[4],
    sigma[0][2] = s[5];
    solution.vertex_von_mises[v] = von_mises(sigma / vertex_count[v]);
  }
}

// @sect3{Probes}
//
// A probe is evaluated in the lowest-numbered locally owned hex that contains it; the ranks agree on the
// lowest such hex overall, and that hex's owner reports the values. A point that no hex holds exactly (a
// probe moved just inside the fan-triangulated boundary can lie outside the curved trilinear hex behind it:
// the default scenario's incisal point, 0.04 mm off the swept core's mesh) is looked for again with a
// tolerance of 5 % of the unit cell, and evaluated at its projection onto that hex.
void ElasticitySolver::evaluate_probes() {
  const FEValuesExtractors::Vector displacements(0);
  for (const Vec3& p : problem.probes) {
    const Point<dim> point = to_point(p);
    int best_hex = std::numeric_limits<int>::max();
    int global_best = best_hex;
    std::vector<double> values(4, 0.0);
    for (const double tolerance : {1e-10, 0.05}) {
      for (const auto& cell : dof_handler.active_cell_iterators()) {
        if (!cell->is_locally_owned() || static_cast<int>(cell->index()) >= best_hex) continue;
        // A cheap bounding-box test first (grown by the tolerance): the inverse mapping is a Newton
        // iteration.
        const auto box = cell->bounding_box();
        const double margin = tolerance * cell->diameter() + 1e-10;
        bool inside_box = true;
        for (unsigned int d = 0; d < dim; ++d)
          inside_box &= point[d] >= box.lower_bound(d) - margin && point[d] <= box.upper_bound(d) + margin;
        if (!inside_box) continue;
        Point<dim> unit;
        try {
          unit = mapping.transform_real_to_unit_cell(cell, point);
        } catch (const typename Mapping<dim>::ExcTransformationFailed&) {
          continue;
        }
        if (!GeometryInfo<dim>::is_inside_unit_cell(unit, tolerance)) continue;
        unit = GeometryInfo<dim>::project_to_unit_cell(unit);
        FEValues<dim> fe_values(mapping, fe, Quadrature<dim>(unit), update_values | update_gradients);
        fe_values.reinit(cell);
        std::vector<Tensor<1, dim>> u(1);
        std::vector<SymmetricTensor<2, dim>> eps(1);
        fe_values[displacements].get_function_values(locally_relevant_solution, u);
        fe_values[displacements].get_function_symmetric_gradients(locally_relevant_solution, eps);
        const Lame l = lame(material_of(cell->index()));
        const SymmetricTensor<2, dim> sigma =
            l.lambda * trace(eps[0]) * unit_symmetric_tensor<dim>() + 2.0 * l.mu * eps[0];
        best_hex = static_cast<int>(cell->index());
        values = {u[0][0], u[0][1], u[0][2], von_mises(sigma)};
      }
      global_best = Utilities::MPI::min(best_hex, mpi_communicator);
      if (global_best != std::numeric_limits<int>::max()) break;
    }
    if (best_hex != global_best) std::fill(values.begin(), values.end(), 0.0);
    Utilities::MPI::sum(values, mpi_communicator, values);
    ProbeValue probe;
    probe.point = p;
    probe.found = global_best != std::numeric_limits<int>::max();
    probe.hex = probe.found ? global_best : -1;
    probe.displacement = {values[0], values[1], values[2]};
    probe.von_mises = values[3];
    solution.probes.push_back(probe);
  }
}

// @sect3{Errors against a reference solution}
//
// For manufactured solutions: the L2 norm of u_h - u and the H1 seminorm of the error, integrated with a
// quadrature two orders more accurate than the assembly's so that the integration error does not pollute
// the convergence rates.
void ElasticitySolver::compute_errors() {
  if (!problem.reference_displacement) return;
  const QGauss<dim> error_quadrature(problem.degree + 3);
  const FEValuesExtractors::Vector displacements(0);
  FEValues<dim> fe_values(mapping, fe, error_quadrature,
                          update_values | update_gradients | update_quadrature_points | update_JxW_values);
  std::vector<Tensor<1, dim>> u(error_quadrature.size());
  std::vector<Tensor<2, dim>> grad_u(error_quadrature.size());
  double l2 = 0.0, h1 = 0.0;
  for (const auto& cell : dof_handler.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fe_values.reinit(cell);
    fe_values[displacements].get_function_values(locally_relevant_solution, u);
    fe_values[displacements].get_function_gradients(locally_relevant_solution, grad_u);
    for (unsigned int q = 0; q < error_quadrature.size(); ++q) {
      const Vec3 x = to_vec3(fe_values.quadrature_point(q));
      const Vec3 exact = problem.reference_displacement(x);
      for (unsigned int c = 0; c < dim; ++c) l2 += std::pow(u[q][c] - exact[c], 2) * fe_values.JxW(q);
      if (problem.reference_gradient) {
        const std::array<Vec3, 3> g = problem.reference_gradient(x);
        for (unsigned int i = 0; i < dim; ++i)
          for (unsigned int j = 0; j < dim; ++j)
            h1 += std::pow(grad_u[q][i][j] - g[i][j], 2) * fe_values.JxW(q);
      }
    }
  }
  solution.l2_error = std::sqrt(Utilities::MPI::sum(l2, mpi_communicator));
  if (problem.reference_gradient)
    solution.h1_seminorm_error = std::sqrt(Utilities::MPI::sum(h1, mpi_communicator));
}

ElasticitySolution ElasticitySolver::run() {
  using Clock = std::chrono::steady_clock;
  auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const auto start = Clock::now();

  make_grid();
  identify_patch_faces();
  setup_system();
  solution.setup_seconds = seconds_since(start);

  const auto assembly_start = Clock::now();
  assemble_system();
  solution.assembly_seconds = seconds_since(assembly_start);

  const auto solve_start = Clock::now();
  solve();
  solution.solve_seconds = seconds_since(solve_start);

  compute_reactions();
  compute_vertex_displacements();
  compute_stresses();
  evaluate_probes();
  compute_errors();

  solution.ranks = static_cast<int>(Utilities::MPI::n_mpi_processes(mpi_communicator));
  // Every rank reports the slowest rank's time, so that all ranks return the same solution.
  solution.seconds = Utilities::MPI::max(seconds_since(start), mpi_communicator);
  return solution;
}

}  // namespace

ElasticitySolution solve_elasticity(const ElasticityProblem& problem) {
  if (!problem.mesh) throw InputError("elasticity: no hex mesh given");
  validate_problem(problem);
  ElasticitySolver solver(problem);
  return solver.run();
}

}  // namespace hexbite
