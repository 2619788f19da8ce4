// MPI (and, through deal.II, PETSc and Trilinos) initialisation for programs that call the solver.
//
// Create one MpiSession at the top of main() (or as a global object in a test program) and keep it alive
// while any solver call runs; it finalizes MPI when the last session object goes away. Without mpirun the
// program runs as a single rank. Further sessions created while one is alive share it.
#pragma once

namespace hexbite {

class MpiSession {
 public:
  // Uses the program's arguments (MPI may consume its own options from them).
  MpiSession(int& argc, char**& argv);
  // For programs without access to argc/argv (test executables with a library main()).
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  // This process's rank in MPI_COMM_WORLD and the number of ranks (0 and 1 when no session was started).
  static int rank();
  static int size();
  // The smallest of `value` over all ranks (collective: every rank must call it); `value` itself when
  // there is one rank. For decisions that every rank must take alike.
  static double min_over_ranks(double value);
};

}  // namespace hexbite
