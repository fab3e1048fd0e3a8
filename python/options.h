#pragma once
// Options from Python keywords, through the option tables of render/render_request.h: each value
// checked as the command line checks its text, so both refuse the same values.
#include <string>

#include "bindings.h"
#include "render/render_request.h"
#include "util/error.h"

namespace lat::py {

// Sets one option from a Python value: TypeError for a value of the wrong kind, InputError for
// one the option's check refuses ("spp: 0 is not in 1 to 65536").
template <class Target>
void set_option(Target& target, const OptionEntry<Target>& e, const pyb::handle& value) {
    const std::string name = e.python_name();
    const OptionField field = e.field(target);
    const auto require = [](const std::string& problem) {
        if (!problem.empty()) throw InputError(problem);
    };
    const bool is_int = pyb::isinstance<pyb::int_>(value) && !pyb::isinstance<pyb::bool_>(value);
    if (int* const* p = std::get_if<int*>(&field)) {
        if (!is_int) throw pyb::type_error(name + ": expected an integer");
        const long long v = value.cast<long long>();
        require(check_option_value(name, e.check, v));
        **p = static_cast<int>(v);
    } else if (double* const* d = std::get_if<double*>(&field)) {
        if (!is_int && !pyb::isinstance<pyb::float_>(value)) throw pyb::type_error(name + ": expected a number");
        const double v = value.cast<double>();
        require(check_option_value(name, e.check, v));
        **d = v;
    } else {
        if (!pyb::isinstance<pyb::str>(value)) throw pyb::type_error(name + ": expected a string");
        const std::string v = value.cast<std::string>();
        require(check_option_value(name, e.check, v));
        if (std::string* const* s = std::get_if<std::string*>(&field)) **s = v;
        if (const ChoiceSetter* set = std::get_if<ChoiceSetter>(&field)) (*set)(v);
    }
}

}  // namespace lat::py
