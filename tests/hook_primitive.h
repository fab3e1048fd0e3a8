#pragma once
// The hook of the paper's Figure 1 (sigma = 1) as a chain, and its lattice at sigma^-1 = 2: the
// small primitive the table tests share.
#include "geometry/chain.h"
#include "lattice/table.h"

namespace lat::test {

inline const ChainShape& hook() {
    static const ChainShape s({{{1, 1, 1}, 0.5}, {{1, 1, 3}, 0.5}, {{3, 1, 3}, 0.5}, {{3, 1, 2}, 0.5}},
                              {{0, 1, 0.5}, {1, 2, 0.5}, {2, 3, 0.5}});
    return s;
}
inline const TableContext kHookContext{{8, 4, 8}, 0.5, 1.0, &hook()};

}  // namespace lat::test
