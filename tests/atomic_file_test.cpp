// Writes through a unique temporary (util/atomic_file.h) and stopping on SIGINT/SIGTERM
// (util/interrupt.h): nothing partial or temporary is ever left behind.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <csignal>
#include <string>
#include <thread>
#include <vector>

#include "input_error.h"
#include "render/modes/integrators.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "util/atomic_file.h"
#include "util/interrupt.h"

namespace lat {
namespace {

using test::error_of;
using test::slurp;
using test::TempDir;

// Clears a received signal at the end of a test, whatever happens in it.
struct SignalReset {
    SignalReset() { install_interrupt_handlers(); }
    ~SignalReset() { clear_interrupt(); }
};

TEST(AtomicFile, TemporaryIsUniqueBesideTheTargetAndRenamedOnCommit) {
    TempDir dir;
    const std::string target = dir.file("out.json");
    AtomicFile a(target), b(target);
    EXPECT_NE(a.temp_path(), b.temp_path());
    EXPECT_EQ(a.temp_path().rfind(target + ".tmp-", 0), 0u) << a.temp_path();
    EXPECT_EQ(a.temp_path().size(), target.size() + 11);  // ".tmp-" and six random characters
    a.write("first", 5);
    b.write("second", 6);
    a.commit();
    b.commit();  // the last rename wins; neither fails
    EXPECT_EQ(slurp(target), "second");
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.json"});
}

TEST(AtomicFile, PermissionsFollowTheUmaskNotMkstemp) {
    TempDir dir;
    const mode_t old = ::umask(022);
    {
        AtomicFile f(dir.file("a"));
        f.commit();
    }
    ::umask(old);
    struct stat st {};
    ASSERT_EQ(::stat(dir.file("a").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0644u);
}

TEST(AtomicFile, UncommittedTemporaryIsRemoved) {
    TempDir dir;
    const std::size_t before = temp_file_count();
    {
        AtomicFile f(dir.file("out.png"));
        f.write("partial", 7);
        EXPECT_EQ(temp_file_count(), before + 1);
    }
    EXPECT_EQ(temp_file_count(), before);
    EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, ErrorsNameTheTargetAndTheKindOfFile) {
    TempDir dir;
    EXPECT_EQ(
        error_of([&] { AtomicFile f(dir.file("no/such/x.lht"), "lattice table"); }),
        dir.file("no/such/x.lht") + ": cannot write lattice table: No such file or directory");
    EXPECT_EQ(error_of([&] { AtomicFile f(dir.path().string()); }),
              dir.path().string() + ": cannot write: Is a directory");
}

TEST(AtomicFile, RemoveTempFilesRemovesEveryLiveTemporary) {
    TempDir dir;
    AtomicFile a(dir.file("a")), b(dir.file("b"));
    EXPECT_EQ(dir.entries().size(), 2u);
    remove_temp_files();
    EXPECT_TRUE(dir.entries().empty());
    EXPECT_EQ(temp_file_count(), 0u);
}

TEST(AtomicFile, ConcurrentWritersOfOneTargetNeverFail) {
    TempDir dir;
    const std::string target = dir.file("stats.json");
    std::vector<std::thread> threads;
    std::vector<std::string> errors(8);
    for (std::size_t t = 0; t < errors.size(); ++t)
        threads.emplace_back([&, t] {
            for (int i = 0; i < 50 && errors[t].empty(); ++i)
                errors[t] = error_of([&] {
                    AtomicFile f(target);
                    f.write("{}\n", 3);
                    f.commit();
                });
        });
    for (std::thread& th : threads) th.join();
    for (const std::string& e : errors) EXPECT_EQ(e, "");
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"stats.json"});
}

TEST(Interrupt, SignalStopsWritesAndLeavesNothing) {
    const SignalReset reset;
    TempDir dir;
    AtomicFile f(dir.file("out.png"));
    f.write("abc", 3);
    std::raise(SIGTERM);  // only sets the flag
    EXPECT_EQ(interrupt_signal(), SIGTERM);
    try {
        f.commit();
        ADD_FAILURE() << "commit went ahead after SIGTERM";
    } catch (const Interrupted& e) {
        EXPECT_EQ(e.exit_code(), 143);
    }
    EXPECT_EQ(dir.entries().size(), 1u);  // the temporary, until the destructor
}

TEST(Interrupt, RenderStopsAtTheNextTile) {
    const SignalReset reset;
    const Scene s = load_scene_text(R"({"camera": {"eye": [0, -6, 1], "look_at": [0, 0, 0],
        "fov_y_deg": 40, "width": 64, "height": 64},
        "materials": {"m": {}}, "objects": [{"type": "sphere", "radius": 1, "material": "m"}]})",
                                    "scene.json");
    const TracedScene rs(s);
    std::raise(SIGINT);
    try {
        render_exact(rs, {});
        ADD_FAILURE() << "the render finished after SIGINT";
    } catch (const Interrupted& e) {
        EXPECT_EQ(e.exit_code(), 130);
        EXPECT_STREQ(e.what(), "interrupted");
    }
}

}  // namespace
}  // namespace lat
