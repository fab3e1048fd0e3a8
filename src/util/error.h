#pragma once
// Errors a user can cause (bad scene, missing table, impossible size) are InputErrors: the
// command line prints the message, which names the file and the place in it, and exits with 2.
// Broken invariants are programming errors and use assert.
#include <stdexcept>
#include <string>
#include <string_view>

namespace lat {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// "file: where: what", leaving out empty parts.
std::string located_message(const std::string& file, const std::string& where,
                            const std::string& what);

// Bytes from a file, fit to quote in a message: control bytes, DEL and bytes of 0x80 and above
// written as \xNN (so a NUL cannot cut the message short nor a CR overwrite it), at most
// max_bytes of the input, "..." when there was more.
std::string printable(std::string_view bytes, std::size_t max_bytes = 40);
// A message made fit for one line of a terminal: control bytes and DEL written as \xNN (text
// quoted from a file may hold them; UTF-8 stays), at most max_bytes long. Readers cap what they
// quote (printable, quoted); this bound is a backstop that leaves room for the place in a
// deeply nested scene (a CSG tree of 256 levels names a few kB of path).
std::string message_line(std::string_view message, std::size_t max_bytes = 16384);
// printable(bytes) in single quotes.
std::string quoted(std::string_view bytes, std::size_t max_bytes = 40);
// A number in a message, to `digits` significant digits (printf's %g).
std::string format_number(double v, int digits = 6);

}  // namespace lat
