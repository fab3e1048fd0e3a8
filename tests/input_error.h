#pragma once
// The message of the InputError a call throws, for tests of user-facing errors.
#include <string>

#include "util/error.h"

namespace lat::test {

// The message of the InputError that f throws, or "" if it throws none.
template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace lat::test
