// Internal: the front end's loops on oneTBB (in the caller's task arena, so
// `ofv compare --jobs N` still uses N threads). Their results do not depend
// on the threads.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <vector>

namespace ofv::perception::detail {

/// f(i) for every i in [0, n), ranges of about `grain` in parallel; for
/// loops whose iterations write only their own results.
template <typename F>
void for_each_index(std::size_t n, std::size_t grain, const F& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) f(i);
  });
}

/// f(i, part) for every i in [0, n), 16 ranges of i in parallel, each
/// appending to its own `part` of `parts`: the parts in order hold what one
/// loop over i in order would have appended.
template <typename T, typename F>
void collect_in_parallel(std::size_t n, std::vector<std::vector<T>>& parts, const F& f) {
  constexpr std::size_t kParts = 16;
  parts.resize(kParts);
  for_each_index(kParts, 1, [&](std::size_t k) {
    parts[k].clear();
    for (std::size_t i = n * k / kParts; i < n * (k + 1) / kParts; ++i) f(i, parts[k]);
  });
}

}  // namespace ofv::perception::detail
