#pragma once
// A span list borrowed for the length of a scope from a per-thread stack: tracing allocates
// nothing once the stack is warm, and nested users each get a list of their own (a CSG tree
// that is a leaf of another, a lattice leaf of a CSG primitive, the nodes of one tree).
// Inline: CSG evaluation borrows two a node, and an out-of-line call cost 2 % on csg12.
#include <cassert>
#include <deque>

#include "geometry/shape.h"

namespace lat {

namespace scratch_detail {
inline thread_local std::deque<SpanList> pool;  // a deque: growing it keeps references valid
inline thread_local std::size_t depth = 0;
inline SpanList& borrow() {
    std::deque<SpanList>& p = pool;
    if (p.size() <= depth) p.resize(depth + 1);
    return p[depth++];
}
}  // namespace scratch_detail

class ScratchSpans {
public:
    ScratchSpans() : list_(scratch_detail::borrow()) { list_.clear(); }  // an empty list
    ~ScratchSpans() {
        using namespace scratch_detail;
        assert(depth > 0 && &pool[depth - 1] == &list_);  // returned in reverse order
        --depth;
    }
    ScratchSpans(const ScratchSpans&) = delete;
    ScratchSpans& operator=(const ScratchSpans&) = delete;

    SpanList& operator*() { return list_; }
    SpanList* operator->() { return &list_; }

private:
    SpanList& list_;
};

}  // namespace lat
