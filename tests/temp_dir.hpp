#pragma once
// A fresh folder under the system's temporary folder for one test, removed at its end.
#include <doctest/doctest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace ddemap::test {

struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& tag = "test") {
        std::string t = (std::filesystem::temp_directory_path() / ("ddemap-" + tag + "-XXXXXX")).string();
        REQUIRE(::mkdtemp(&t[0]) != nullptr);
        path = t;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    /// The path of `name` inside the folder.
    std::string operator/(const std::string& name) const { return (path / name).string(); }
    /// Writes `text` into the file `name` inside the folder and returns its path.
    std::string file(const std::string& name, const std::string& text) const {
        std::ofstream(path / name, std::ios::binary) << text;
        return (path / name).string();
    }
};

}  // namespace ddemap::test
