// Helper threads that the system may refuse: under an address-space limit (ulimit -v) a new thread's stack
// may not fit, and ulimit -u caps the threads of a user. std::thread's constructor then throws
// std::system_error, which a caller that only wants more speed should take as "do the work yourself".
// Hand-written: the standard library has no "try" form of std::thread's constructor.
#pragma once

#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace hexbite {

// Starts a thread running f() and appends it to `helpers`; false, with nothing started, when the system
// refuses the thread.
template <class F>
bool start_helper_thread(std::vector<std::thread>& helpers, F&& f) {
  try {
    helpers.emplace_back(std::forward<F>(f));
    return true;
  } catch (const std::system_error&) {
    return false;
  }
}

}  // namespace hexbite
