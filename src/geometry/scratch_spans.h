#pragma once
// A span list borrowed for the length of a scope from a per-thread stack: tracing allocates
// nothing once the stack is warm, and nested users each get a list of their own (a CSG tree
// that is a leaf of another, a lattice leaf of a CSG primitive, the nodes of one tree).
#include "geometry/shape.h"

namespace lat {

class ScratchSpans {
public:
    ScratchSpans();  // an empty list
    ~ScratchSpans();
    ScratchSpans(const ScratchSpans&) = delete;
    ScratchSpans& operator=(const ScratchSpans&) = delete;

    SpanList& operator*() { return list_; }
    SpanList* operator->() { return &list_; }

private:
    SpanList& list_;
};

}  // namespace lat
