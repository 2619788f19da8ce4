// MpiSession: a reference-counted wrapper around deal.II's MPI_InitFinalize, which also initialises the
// libraries deal.II uses under MPI (PETSc, p4est) and finalizes them in the right order.
#include "solver/mpi_session.h"

#include <deal.II/base/mpi.h>
#include <deal.II/lac/la_parallel_block_vector.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector_memory.h>
#include <stdlib.h>

namespace hexbite {
namespace {

// One initialisation per process: MPI cannot be initialised again after it was finalized. A plain pointer,
// not a smart one: a static with a destructor could be destroyed before a global MpiSession of another
// translation unit (static destruction order across files is unspecified), which would then free it twice.
int session_count = 0;
dealii::Utilities::MPI::MPI_InitFinalize* mpi_init = nullptr;

// MPI_Init may keep pointers into argv, so the fallback arguments must outlive the session.
int fallback_argc = 1;
char fallback_name[] = "hexbite";
char* fallback_argv_storage[] = {fallback_name, nullptr};
char** fallback_argv = fallback_argv_storage;

void start(int& argc, char**& argv) {
  // One thread per rank: the solver's assembly is sequential per rank and the machine's cores are
  // better used by MPI ranks than by threads competing with them.
  if (session_count++ > 0) return;
  // Without a launcher (no mpirun: a singleton) PMIx's shared-memory datastore is not needed, and its files
  // could not be made under a file size limit (ulimit -f 2000 aborted every `hexbite run` inside MPI_Init,
  // although a run writes far less): the plain hash store instead, unless the user chose one.
  if (std::getenv("PMIX_RANK") == nullptr && std::getenv("OMPI_COMM_WORLD_SIZE") == nullptr)
    setenv("PMIX_MCA_gds", "hash", 0);
  mpi_init = new dealii::Utilities::MPI::MPI_InitFinalize(argc, argv, 1);
  // MPI_InitFinalize's destructor empties deal.II's pools of MPI vectors (function-local statics, created on
  // first use, e.g. by CG). A pool first used after a global MpiSession was built would be destroyed before
  // it at exit, and the session's destructor would then touch a dead pool. Creating the pools now, inside
  // this constructor, makes them outlive every session, global or local.
  using namespace dealii;
  GrowingVectorMemory<LinearAlgebra::distributed::Vector<double>>::release_unused_memory();
  GrowingVectorMemory<LinearAlgebra::distributed::BlockVector<double>>::release_unused_memory();
  GrowingVectorMemory<LinearAlgebra::distributed::Vector<float>>::release_unused_memory();
  GrowingVectorMemory<LinearAlgebra::distributed::BlockVector<float>>::release_unused_memory();
  GrowingVectorMemory<TrilinosWrappers::MPI::Vector>::release_unused_memory();
  GrowingVectorMemory<TrilinosWrappers::MPI::BlockVector>::release_unused_memory();
}

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  start(argc, argv);
}

MpiSession::MpiSession() {
  start(fallback_argc, fallback_argv);
}

MpiSession::~MpiSession() {
  if (--session_count == 0) {
    delete mpi_init;
    mpi_init = nullptr;
  }
}

// Without a session (commands that never solve skip MPI's start-up) the program is rank 0 of 1.
int MpiSession::rank() {
  if (!dealii::Utilities::MPI::job_supports_mpi()) return 0;
  return static_cast<int>(dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD));
}

int MpiSession::size() {
  if (!dealii::Utilities::MPI::job_supports_mpi()) return 1;
  return static_cast<int>(dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD));
}

double MpiSession::min_over_ranks(double value) {
  if (size() == 1) return value;
  return dealii::Utilities::MPI::min(value, MPI_COMM_WORLD);
}

}  // namespace hexbite
