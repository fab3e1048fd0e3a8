#include "geometry/scratch_spans.h"

#include <cassert>
#include <deque>

namespace lat {
namespace {

thread_local std::deque<SpanList> t_pool;  // a deque: growing it keeps references valid
thread_local std::size_t t_depth = 0;

SpanList& borrow() {
    if (t_pool.size() <= t_depth) t_pool.resize(t_depth + 1);
    return t_pool[t_depth++];
}

}  // namespace

ScratchSpans::ScratchSpans() : list_(borrow()) { list_.clear(); }

ScratchSpans::~ScratchSpans() {
    assert(t_depth > 0 && &t_pool[t_depth - 1] == &list_);  // returned in reverse order
    --t_depth;
}

}  // namespace lat
