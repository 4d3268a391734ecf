// What a Krylov solver needs besides its operators: the sum of a scalar over
// everything that holds a part of its vectors (the ranks of a run,
// core/parallel/comm.hpp; a device would be another). Each part sums its own
// entries first, so with one part the result is the local sum, bit for bit.
#pragma once
#include "kernels/types.hpp"

namespace tresca {

class Reduction {
 public:
  virtual ~Reduction() = default;
  virtual real sum(real local) const = 0;
};

}  // namespace tresca
