// Files in and out: input text (BOM, CRLF, folders), output checks and atomic output sets.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ddemap/io/files.hpp"
#include "temp_dir.hpp"

using namespace ddemap;
namespace fs = std::filesystem;
using ddemap::test::TempDir;

namespace {


std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

void spit(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

int entries(const fs::path& dir) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++n;
    }
    return n;
}

}  // namespace

TEST_CASE("input text: a byte-order mark and CRLF line ends are removed, nothing else changes") {
    CHECK(normalize_input_text("\xEF\xBB\xBF" "a,b\r\n1,2\r\n") == "a,b\n1,2\n");
    CHECK(normalize_input_text("a,b\n1,2") == "a,b\n1,2");
    CHECK(normalize_input_text("a\rb\r\n") == "a\rb\n");  // a lone CR is data
    CHECK(normalize_input_text("x\r") == "x");
    CHECK(normalize_input_text("") == "");
    CHECK(normalize_input_text("\xEF\xBB") == "\xEF\xBB");  // not a whole mark
}

TEST_CASE("read_text_file: a folder is refused with a message that says so") {
    TempDir d;
    CHECK_THROWS_WITH_AS(read_text_file(d.path.string()), doctest::Contains("is a folder, expected a file"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_text_file(d / "missing.csv"), doctest::Contains("No such file or directory"), std::invalid_argument);
    spit(d / "v.csv", "\xEF\xBB\xBFname,k1,k2,th,tau\r\nx,0.2,0.4,1.5,0.3\r\n");
    CHECK(read_text_file(d / "v.csv") == "name,k1,k2,th,tau\nx,0.2,0.4,1.5,0.3\n");
}

TEST_CASE("check_output_file: folders and files in the wrong place are found before any work") {
    TempDir d;
    spit(d / "plain", "x");
    CHECK_THROWS_WITH_AS(check_output_file(d / "plain/a.csv"), doctest::Contains("is a file, not a folder"), std::invalid_argument);
    fs::create_directory(d / "dir.csv");
    CHECK_THROWS_WITH_AS(check_output_file(d / "dir.csv"), doctest::Contains("is a folder"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(check_output_file(d / "none/a.csv"), doctest::Contains("does not exist"), std::invalid_argument);
    CHECK_NOTHROW(check_output_file(d / "new.csv"));
    CHECK_NOTHROW(check_output_file("/dev/null"));
}

TEST_CASE("write_files_atomic: a new set, a replaced set, and no temporary file left") {
    TempDir d;
    write_files_atomic({{d / "a.csv", "new a"}, {d / "a.json", "new j"}});
    CHECK(slurp(d / "a.csv") == "new a");
    CHECK(slurp(d / "a.json") == "new j");
    spit(d / "b.csv", "old b");
    ::chmod((d / "b.csv").c_str(), 0640);
    write_file_atomic(d / "b.csv", "new b");
    CHECK(slurp(d / "b.csv") == "new b");
    struct stat st {};
    REQUIRE(::stat((d / "b.csv").c_str(), &st) == 0);
    CHECK((st.st_mode & 0777) == 0640);  // an existing file keeps its mode
    CHECK(entries(d.path) == 3);
}

TEST_CASE("write_files_atomic: a link is written through, a device is written into") {
    TempDir d;
    fs::create_directory(d / "real");
    spit(d / "real/t.svg", "old");
    fs::create_symlink("real/t.svg", d / "t.svg");
    write_file_atomic(d / "t.svg", "new");
    CHECK(fs::is_symlink(d / "t.svg"));
    CHECK(slurp(d / "real/t.svg") == "new");
    CHECK(entries(d.path / "real") == 1);
    fs::create_symlink("real/dangling.svg", d / "dangling.svg");  // a link to a missing file creates it
    write_file_atomic(d / "dangling.svg", "made");
    CHECK(fs::is_symlink(d / "dangling.svg"));
    CHECK(slurp(d / "real/dangling.svg") == "made");
    write_file_atomic("/dev/null", "into the device");
    CHECK(fs::is_character_file("/dev/null"));
    if (fs::exists("/dev/full")) {
        CHECK_THROWS_WITH_AS(write_file_atomic("/dev/full", "x"), doctest::Contains("No space left on device"), WriteError);
        CHECK(fs::is_character_file("/dev/full"));
    }
}

TEST_CASE("write_files_atomic: a failed move puts every old file back (test hook move:K)") {
    TempDir d;
    spit(d / "r.csv", "old csv");
    spit(d / "r.json", "old json");
    for (const char* fault : {"move:2", "move:3", "named,move:2"}) {
        CAPTURE(fault);
        ::setenv("DDEMAP_TEST_FAULT", fault, 1);
        CHECK_THROWS_WITH_AS(write_files_atomic({{d / "r.csv", "new csv"}, {d / "r.json", "new json"}, {d / "r.svg", "new svg"}}),
                             doctest::Contains("Input/output error"), WriteError);
        ::unsetenv("DDEMAP_TEST_FAULT");
        CHECK(slurp(d / "r.csv") == "old csv");
        CHECK(slurp(d / "r.json") == "old json");
        CHECK(!fs::exists(d / "r.svg"));
        CHECK(entries(d.path) == 2);
    }
    ::setenv("DDEMAP_TEST_FAULT", "named", 1);  // the path of file systems without O_TMPFILE
    write_files_atomic({{d / "r.csv", "new csv"}, {d / "r.json", "new json"}});
    ::unsetenv("DDEMAP_TEST_FAULT");
    CHECK(slurp(d / "r.csv") == "new csv");
    CHECK(entries(d.path) == 2);
}

TEST_CASE("write_files_atomic: a folder where a file is needed fails before anything changes") {
    TempDir d;
    spit(d / "s.csv", "old");
    fs::create_directory(d / "s.json");
    CHECK_THROWS_WITH_AS(write_files_atomic({{d / "s.csv", "new"}, {d / "s.json", "new"}}), doctest::Contains("Is a directory"), WriteError);
    CHECK(slurp(d / "s.csv") == "old");
    CHECK(entries(d.path) == 2);
}

TEST_CASE("write_files_atomic: stale members of a set are removed with it, or kept when it fails") {
    TempDir d;
    spit(d / "x.csv", "old");
    spit(d / "x-boundaries.csv", "old boundaries");
    fs::create_directory(d / "x-dir.csv");
    ::setenv("DDEMAP_TEST_FAULT", "move:2", 1);
    CHECK_THROWS_AS(write_files_atomic({{d / "x.csv", "new"}}, {d / "x-boundaries.csv"}), WriteError);
    ::unsetenv("DDEMAP_TEST_FAULT");
    CHECK(slurp(d / "x.csv") == "old");
    CHECK(slurp(d / "x-boundaries.csv") == "old boundaries");
    CHECK(entries(d.path) == 3);
    write_files_atomic({{d / "x.csv", "new"}}, {d / "x-boundaries.csv", d / "x-missing.csv", d / "x-dir.csv"});
    CHECK(slurp(d / "x.csv") == "new");
    CHECK(!fs::exists(d / "x-boundaries.csv"));
    CHECK(fs::is_directory(d / "x-dir.csv"));  // only regular files are removed
    CHECK(entries(d.path) == 2);
}

TEST_CASE("write_files_atomic: the next write into a folder removes the temporary files that killed writers left there, whatever their name") {
    TempDir d;
    // a process that has ended: a child reaped (its PID is free); this process is alive
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) ::_exit(0);
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    const std::string dead = ".other.csv.ddemap-" + std::to_string(child) + "-1.tmp";
    const std::string alive = ".mine.csv.ddemap-" + std::to_string(::getpid()) + "-7.tmp";
    spit(d / dead, "half written");
    spit(d / alive, "being written");
    spit(d / ".keep.tmp", "not ours");
    write_file_atomic(d / "x.csv", "x");
    CHECK(!fs::exists(d / dead));
    CHECK(fs::exists(d / alive));
    CHECK(fs::exists(d / ".keep.tmp"));
    CHECK(slurp(d / "x.csv") == "x");
}

TEST_CASE("check_output_file: a folder that refuses new files is found before the work, also for root (a link into /proc)") {
    TempDir d;
    fs::create_symlink("/proc/self/status", d / "o.csv");
    CHECK_THROWS_WITH_AS(check_output_file(d / "o.csv"), doctest::Contains("the folder '/proc/self' is not writable"), std::invalid_argument);
    CHECK_NOTHROW(check_output_file(d / "fine.csv"));
    CHECK(entries(d.path) == 1);  // the probe file is gone
}
