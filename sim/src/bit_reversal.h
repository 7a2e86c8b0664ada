// Orders that spread over a sequence, shared inside ofv_sim by the renderer
// (blocks of the object's samples) and the hindsight planner (lattice views).
#pragma once

#include <cstddef>

namespace ofv::sim::detail {

// The fewest bits that count to n: 1 << bits_for(n) >= n.
inline int bits_for(std::size_t n) {
  int bits = 0;
  while ((std::size_t{1} << bits) < n) ++bits;
  return bits;
}

// i with its lowest `bits` bits in reverse order: i = 0, 1, 2, 3 ... over
// 1 << bits gives 0, half, a quarter, three quarters ..., each next one
// farthest from those before.
inline std::size_t bit_reversed(std::size_t i, int bits) {
  std::size_t r = 0;
  for (int bit = 0; bit < bits; ++bit) r |= ((i >> bit) & 1u) << (bits - 1 - bit);
  return r;
}

}  // namespace ofv::sim::detail
