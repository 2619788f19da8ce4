// MpiSession: a reference-counted wrapper around deal.II's MPI_InitFinalize, which also initialises the
// libraries deal.II uses under MPI (PETSc, p4est) and finalizes them in the right order.
#include "solver/mpi_session.h"

#include <deal.II/base/mpi.h>

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
  if (session_count++ == 0) mpi_init = new dealii::Utilities::MPI::MPI_InitFinalize(argc, argv, 1);
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

int MpiSession::rank() {
  return static_cast<int>(dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD));
}

int MpiSession::size() {
  return static_cast<int>(dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD));
}

}  // namespace hexbite
