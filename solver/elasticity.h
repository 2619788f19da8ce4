// Linear elasticity on a pure hexahedral mesh: the problem and its results as plain data, and the one
// function that solves it with deal.II (vector Q1 or Q2 elements, CG with Trilinos ML algebraic multigrid or
// a direct solver), serially or distributed over the MPI ranks of the calling program.
//
// This header deliberately includes no deal.II header: deal.II compiles slowly and the scenario loader, the
// command line and the writers include this file. Units throughout: mm, N, MPa (N/mm^2), mJ (N mm).
// The caller must keep an MpiSession (solver/mpi_session.h) alive around every call to solve_elasticity().
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "common/error.h"
#include "mesher/hex_mesh.h"

namespace hexbite {

// A boundary face of the hex mesh, given by its four vertex ids in any order. The solver matches it against
// the boundary faces of the mesh and rejects (InputError) a quad that is not one. The mesher's
// extract_boundary() (mesher/hex_boundary.h) lists the candidates.
using BoundaryQuad = std::array<int, 4>;

// Isotropic linear elastic material. Bone (DESIGN.md section 3): E = 11000 MPa, Poisson 0.28.
struct Material {
  double youngs_modulus = 11000.0;  // MPa
  double poisson_ratio = 0.28;
};

// A muscle insertion (or any other load): a uniform traction t = force / area over the patch, so that the
// traction integrates exactly to `force` whatever the patch's shape.
struct TractionPatch {
  std::string name;
  std::vector<BoundaryQuad> faces;
  Vec3 force{0.0, 0.0, 0.0};  // N, total over the patch
};

// A support: either fixed (Dirichlet) in the selected components or, when spring_stiffness > 0, an elastic
// foundation in the selected components (surface traction -k u, k in N/mm^3 = N/mm^2 per mm of
// displacement). Fixed components take the value of `displacement` (zero when it is empty): the seed's
// "hard nut" is a fixed bite patch with zero displacement.
struct SupportPatch {
  std::string name;
  std::vector<BoundaryQuad> faces;
  std::array<bool, 3> components{true, true, true};  // which of x, y, z the support acts on
  double spring_stiffness = 0.0;                     // N/mm^3; 0 means fixed
  bool is_bite = false;                              // its reaction is the bite force
  std::function<Vec3(const Vec3& x)> displacement;   // prescribed value (mm) for fixed components
};

enum class LinearSolver { kCgAmg, kDirect };

// The direct solver (MUMPS, through Trilinos Amesos) gave up, most often because it could not allocate its
// workspace (under an address-space limit, `ulimit -v`, as batch schedulers set it). The caller may try CG
// with AMG, which needs far less memory.
class DirectSolverError : public RunError {
 public:
  using RunError::RunError;
};

struct SolverSettings {
  LinearSolver linear_solver = LinearSolver::kCgAmg;
  double relative_tolerance = 1e-10;  // of the CG residual, relative to the right-hand side
  int max_iterations = 2000;
};

struct ElasticityProblem {
  const HexMesh* mesh = nullptr;
  Material material;                   // everywhere unless overridden below
  std::vector<Material> hex_material;  // empty, or one entry per hex (overrides `material`)
  std::vector<TractionPatch> loads;
  std::vector<SupportPatch> supports;
  std::vector<Vec3> probes;  // points (mm) where displacement and von Mises are reported
  int degree = 1;            // 1 (trilinear) or 2 (triquadratic) displacement elements
  SolverSettings solver;

  // Verification aids, empty in production runs. A body force (N/mm^3) for manufactured solutions, and a
  // reference displacement field (with its gradient, du_i/dx_j as grad[i][j]) against which the solver
  // measures the L2 and H1-seminorm errors of its solution.
  std::function<Vec3(const Vec3& x)> body_force;
  std::function<Vec3(const Vec3& x)> reference_displacement;
  std::function<std::array<Vec3, 3>(const Vec3& x)> reference_gradient;

  // true: distribute the problem over all ranks of MPI_COMM_WORLD. false: every rank solves its own
  // serial copy (MPI_COMM_SELF), e.g. for independent studies per rank or to compare against serial.
  bool distribute_over_all_ranks = true;
};

// A symmetric stress tensor in MPa, components xx, yy, zz, xy, yz, xz.
using Stress6 = std::array<double, 6>;

struct SupportReaction {
  std::string name;
  bool is_bite = false;
  Vec3 force{0.0, 0.0, 0.0};  // N, the force the support exerts on the bone
  double magnitude = 0.0;
  // Set by a caller that left the support out of the solve (a one-sided contact that would pull the bone;
  // app/run_pipeline.h); its force is then zero. The solver itself never sets it.
  bool released = false;
};

struct ProbeValue {
  Vec3 point{0.0, 0.0, 0.0};
  bool found = false;  // false if the point lies outside the mesh (values are then zero)
  int hex = -1;        // the hex that evaluated it (the lowest index if it lies on a shared face)
  Vec3 displacement{0.0, 0.0, 0.0};
  double von_mises = 0.0;
};

struct ElasticitySolution {
  // Displacement (mm) at every vertex of the mesh, indexed like HexMesh::vertices.
  std::vector<Vec3> vertex_displacement;

  // Forces and the equilibrium check. applied_force is the sum of all tractions and body forces;
  // equilibrium_residual = |applied + sum of reactions| / |applied| (issue 5); when the net applied force
  // is 0 (or below 1e-12 of that fallback: loads that cancel), the denominator is the larger of the sum of
  // |reaction| and the largest single load.
  Vec3 applied_force{0.0, 0.0, 0.0};
  std::vector<SupportReaction> reactions;  // one per support, in the problem's order
  double bite_force = 0.0;                 // magnitude of the summed reactions of the bite supports
  double equilibrium_residual = 0.0;

  double max_displacement = 0.0;  // mm, over the vertices
  Vec3 max_displacement_at{0.0, 0.0, 0.0};

  // Stresses. Per hex: the volume average of the stress tensor, its principal stresses (descending), the
  // volume average of von Mises over the quadrature points, and its maximum over them. Per vertex: the
  // stress tensors evaluated at that corner in every adjacent hex, averaged, and its von Mises stress.
  std::vector<Stress6> hex_stress;
  std::vector<Vec3> hex_principal_stress;
  std::vector<double> hex_von_mises;
  std::vector<double> hex_von_mises_max;
  std::vector<double> vertex_von_mises;
  double von_mises_max = 0.0;  // MPa, over all quadrature points
  Vec3 von_mises_max_at{0.0, 0.0, 0.0};
  double von_mises_p99 = 0.0;  // 99th percentile (nearest rank) of hex_von_mises

  double strain_energy = 0.0;  // mJ = N mm, (1/2) integral of sigma : epsilon over the bone
  std::vector<ProbeValue> probes;

  // Errors against ElasticityProblem::reference_displacement / reference_gradient (-1 when not given).
  double l2_error = -1.0;
  double h1_seminorm_error = -1.0;

  // Solver statistics: CG iterations (0 for the direct solver), wall seconds of the whole solve and of
  // its phases, MPI ranks used, and the number of degrees of freedom.
  int iterations = 0;
  double seconds = 0.0;
  double setup_seconds = 0.0;
  double assembly_seconds = 0.0;
  double solve_seconds = 0.0;
  int ranks = 1;
  long long dofs = 0;
};

// Solves the problem. Throws InputError for a malformed problem (no mesh, a face that is not a boundary face
// of the mesh, E <= 0, Poisson outside (-1, 0.5), degree not 1 or 2, no support) and RunError if the linear
// solver fails. Collective: with distribute_over_all_ranks, every rank must call it with the same problem,
// and every rank receives the complete solution.
ElasticitySolution solve_elasticity(const ElasticityProblem& problem);

}  // namespace hexbite
