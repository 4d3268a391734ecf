// Scalar and index types used everywhere. Sizes that exceed 2^31 at large
// mesh levels (dof counts, flat offsets) are 64-bit.
#pragma once
#include <cstdint>

namespace tresca {
using real = double;
using index = std::int64_t;
}  // namespace tresca
