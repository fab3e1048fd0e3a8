#include "util/error.h"

#include <cstdio>

namespace lat {

std::string located_message(const std::string& file, const std::string& where,
                            const std::string& what) {
    std::string out;
    if (!file.empty()) out += file + ": ";
    if (!where.empty()) out += where + ": ";
    return out + what;
}

std::string printable(std::string_view bytes, std::size_t max_bytes) {
    static const char kHex[] = "0123456789abcdef";
    std::string out;
    for (std::size_t i = 0; i < bytes.size() && i < max_bytes; ++i) {
        const auto c = static_cast<unsigned char>(bytes[i]);
        if (c >= 0x20 && c < 0x7f) {
            out += static_cast<char>(c);
        } else {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        }
    }
    if (bytes.size() > max_bytes) out += "...";
    return out;
}

std::string message_line(std::string_view message, std::size_t max_bytes) {
    static const char kHex[] = "0123456789abcdef";
    std::string out;
    for (std::size_t i = 0; i < message.size() && out.size() < max_bytes; ++i) {
        const auto c = static_cast<unsigned char>(message[i]);
        if (c >= 0x20 && c != 0x7f) {
            out += static_cast<char>(c);
        } else {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        }
    }
    if (out.size() >= max_bytes && out.size() < message.size()) out += "...";
    return out;
}

std::string quoted(std::string_view bytes, std::size_t max_bytes) {
    std::string out = "'";
    out += printable(bytes, max_bytes);
    out += '\'';
    return out;
}

std::string format_number(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

}  // namespace lat
