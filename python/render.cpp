// lattice.render: every option of `lattice render`, read from its option table
// (render/render_request.h), so the two never differ in names, checks or defaults.
#include <signal.h>

#include <chrono>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>

#include "bindings.h"
#include "options.h"
#include "render/render_request.h"
#include "scene_object.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/progress.h"
#include "util/threads.h"

namespace lat::py {
namespace {

const OptionEntry<RenderRequest>* find_option(const std::string& python_name) {
    for (const OptionEntry<RenderRequest>& e : render_option_entries())
        if (!e.command_line_only && e.python_name() == python_name) return &e;
    return nullptr;
}

std::string option_list() {
    std::string list;
    for (const OptionEntry<RenderRequest>& e : render_option_entries())
        if (!e.command_line_only) list += (list.empty() ? "" : ", ") + e.python_name();
    return list;
}

RenderRequest read_options(const PyScene& s, const pyb::kwargs& kw, pyb::object& progress) {
    RenderRequest r;
    r.scene = s.scene.file;
    std::set<std::string> given;
    for (const auto& [key, value] : kw) {
        const std::string name = key.cast<std::string>();
        if (name == "progress") {
            progress = pyb::reinterpret_borrow<pyb::object>(value);
            continue;
        }
        const OptionEntry<RenderRequest>* e = find_option(name);
        if (!e) throw pyb::type_error("render() got an unexpected option '" + name + "' (options: " + option_list() + ")");
        if (value.is_none()) continue;
        set_option(r, *e, value);
        given.insert(e->long_name());
    }
    settle_request(r, [&](std::string_view n) { return given.count(std::string(n)) > 0; });
    return r;
}

// For the render: lattice's flag-setting SIGINT and SIGTERM handlers, which the tiles poll, in
// place of Python's (whose Python-level handler would run only once the render returned);
// Python's back afterwards. A signal then raises KeyboardInterrupt (SystemExit for SIGTERM).
class SignalsDuringRender {
public:
    SignalsDuringRender() {
        sigaction(SIGINT, nullptr, &int_);
        sigaction(SIGTERM, nullptr, &term_);
        clear_interrupt();
    }
    ~SignalsDuringRender() {
        sigaction(SIGINT, &int_, nullptr);
        sigaction(SIGTERM, &term_, nullptr);
        clear_interrupt();
    }
    SignalsDuringRender(const SignalsDuringRender&) = delete;
    SignalsDuringRender& operator=(const SignalsDuringRender&) = delete;

private:
    struct sigaction int_ {}, term_ {};
};

// The progress callback as the progress bars' sink, for the render; the first exception it
// raises is raised again once the render is done.
class ProgressCallback {
public:
    explicit ProgressCallback(pyb::object callback) : callback_(std::move(callback)) {}
    // While the render lock is held (the sink is the process's).
    void install() {
        if (callback_.is_none()) return;
        set_progress_sink([this](const std::string& label, double done) {
            const pyb::gil_scoped_acquire gil;
            if (error_) return;
            try {
                callback_(label, done);
            } catch (pyb::error_already_set& e) {
                error_ = std::make_shared<pyb::error_already_set>(std::move(e));
            }
        });
    }
    void uninstall() {
        if (!callback_.is_none()) set_progress_sink({});
    }
    ProgressCallback(const ProgressCallback&) = delete;
    ProgressCallback& operator=(const ProgressCallback&) = delete;
    bool enabled() const { return !callback_.is_none(); }
    void raise_if_failed() {
        if (error_) throw *error_;
    }

private:
    pyb::object callback_;
    std::shared_ptr<pyb::error_already_set> error_;
};

pyb::tuple render(const std::shared_ptr<PyScene>& s, const pyb::kwargs& kw) {
    pyb::object progress = pyb::none();
    const RenderRequest request = read_options(*s, kw, progress);
    check_render_budget(s->scene.camera, request.spp, s->scene.file);
    ProgressCallback callback(progress);
    ModeSettings settings = mode_settings(request);
    settings.progress = callback.enabled();
    ModeResult r;
    RenderTimings t;
    {
        const pyb::gil_scoped_release release;
        const std::lock_guard lock(process_mutex());
        const auto start = std::chrono::steady_clock::now();
        const ThreadLimit limit(request.threads);
        const SignalsDuringRender signals;
        callback.install();
        struct Uninstall {
            ProgressCallback& c;
            ~Uninstall() { c.uninstall(); }
        } const uninstall{callback};
        settings.before_render = [] { install_interrupt_handlers(); };
        r = render_in_mode(s->scene, request.render_mode(), settings);
        throw_if_interrupted();  // a signal after the last tile still stops the caller
        t.loaded = s->load_ms;
        t.written = s->load_ms +
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    callback.raise_if_failed();
    const std::string stats = render_stats_json(request, s->scene, r, t).dump();
    pyb::object dict = pyb::module_::import("json").attr("loads")(stats);
    return pyb::make_tuple(radiance_array(std::move(r.out)), dict);
}

// The options render() takes, with their help: the command line's.
pyb::dict render_options() {
    pyb::dict d;
    for (const OptionEntry<RenderRequest>& e : render_option_entries())
        if (!e.command_line_only) d[pyb::str(e.python_name())] = e.help;
    return d;
}

}  // namespace

std::mutex& process_mutex() {
    static std::mutex m;
    return m;
}

void bind_render(pyb::module_& m) {
    m.def("render", &render, pyb::arg("scene"), R"(Renders a scene; returns (image, stats).

image: H x W x 3 float32 array of linear radiance (row 0 at the top).
stats: dict, the fields of `lattice render --stats`.
Options: those of `lattice render`, with '_' for '-' (render_options() lists them with their
help), e.g. mode="lattice", spp=4, threads=2, footprint="on", sigma_inv=2, lod_budget=1.0;
and progress=callable(label, fraction), called from another thread about ten times a second.
The GIL is released while it renders; Ctrl-C stops it at the next tile (KeyboardInterrupt).
Bad values raise InputError (a ValueError), unknown options TypeError.)");
    m.def("render_options", &render_options, "The options render() takes: {name: help}");
}

}  // namespace lat::py
