#pragma once
// Errors a user can cause (bad scene, missing table, impossible size) are InputErrors: the
// command line prints the message, which names the file and the place in it, and exits with 2.
// Broken invariants are programming errors and use assert.
#include <stdexcept>
#include <string>

namespace lat {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// "file: where: what", leaving out empty parts.
std::string located_message(const std::string& file, const std::string& where,
                            const std::string& what);

}  // namespace lat
