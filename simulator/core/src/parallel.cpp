// Thread counts and the run-time choice of the AVX2 paths.
#include "parallel.hpp"

#include <algorithm>
#include <cstdlib>

#ifdef CLOTHSIM_HAVE_COLLISION
#include <clothsim/collision.hpp>
#endif

namespace clothsim {

int resolve_threads(int n) {
#ifdef _OPENMP
  return n > 0 ? n : omp_get_num_procs();
#else
  (void)n;
  return 1;
#endif
}

int core_count() {
#ifdef _OPENMP
  // the cores this process may use, capped by OMP_NUM_THREADS when that is set lower
  return std::max(1, std::min(omp_get_num_procs(), omp_get_max_threads()));
#else
  return 1;
#endif
}

bool step_splits(const Model& model) {
  const std::size_t n = model.mass_count();
  std::size_t collision = 0;
#ifdef CLOTHSIM_HAVE_COLLISION
  if (model.colliders) collision = detail::collision_work(n, model.colliders->object_count());
#endif
  return std::max(n, collision) >= detail::kTeamWork;  // team() of the mass loops and of the collision
}


}  // namespace clothsim
