#pragma once
// Shared by the libFuzzer targets: every parser reachable from the command line must, for any
// input, either return a value or throw std::invalid_argument (a one-line message); any other
// exception, a crash, a sanitizer report or a hang is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace ddemap::fuzz {

inline std::string text(const std::uint8_t* data, std::size_t size) {
    return std::string(reinterpret_cast<const char*>(data), size);
}

/// Runs `parse`; bad input (std::invalid_argument with a one-line message) is the expected
/// refusal; anything else aborts so that the fuzzer records the input.
template <class F>
int expect_value_or_bad_input(F&& parse) {
    try {
        parse();
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        if (what.empty() || what.find('\n') != std::string::npos) {
            std::fprintf(stderr, "error message is not one line: [%s]\n", what.c_str());
            std::abort();
        }
    }
    return 0;
}

}  // namespace ddemap::fuzz
