// Text checks of the readers and writers (src/core/internal/text.hpp): the UTF-8 validator
// against RFC 3629's table of well-formed byte sequences (and against a brute-force decoder of
// every code point), the error message of a file that is not UTF-8, and the writers' escapes.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "../../src/core/internal/text.hpp"
#include "ddemap/io/csv.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
/// The UTF-8 encoding of code point `cp` (RFC 3629, section 3), written out independently of
/// the validator.
std::string encode(unsigned cp) {
    std::string s;
    if (cp < 0x80) {
        s += static_cast<char>(cp);
    } else if (cp < 0x800) {
        s += static_cast<char>(0xC0 | (cp >> 6));
        s += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
        s += static_cast<char>(0xE0 | (cp >> 12));
        s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        s += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
        s += static_cast<char>(0xF0 | (cp >> 18));
        s += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
        s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        s += static_cast<char>(0x80 | (cp & 0x3F));
    }
    return s;
}
}  // namespace

TEST_CASE("UTF-8: every scalar value's encoding is accepted, surrogates, overlong forms, stray and truncated bytes are not") {
    // every code point: a scalar value (not a surrogate) is well formed, a surrogate is not
    long accepted = 0;
    for (unsigned cp = 0; cp <= 0x10FFFF; ++cp) {
        const bool surrogate = cp >= 0xD800 && cp <= 0xDFFF;
        const std::string s = "a" + encode(cp) + "b";
        const bool ok = detail::invalid_utf8_at(s) == std::string::npos;
        if (ok != !surrogate) {
            CAPTURE(cp);
            FAIL("the validator disagrees with RFC 3629");
        }
        accepted += ok;
    }
    CHECK(accepted == 0x110000 - 0x800);
    // the byte sequences RFC 3629 rules out, each at its offset
    CHECK(detail::invalid_utf8_at("ab\xC0\xAF") == 2);          // overlong '/'
    CHECK(detail::invalid_utf8_at("\xE0\x80\xAF") == 0);        // overlong, 3 bytes
    CHECK(detail::invalid_utf8_at("\xF0\x80\x80\xAF") == 0);    // overlong, 4 bytes
    CHECK(detail::invalid_utf8_at("x\xF4\x90\x80\x80") == 1);   // above U+10FFFF
    CHECK(detail::invalid_utf8_at("\xF5\x80\x80\x80") == 0);    // no such lead byte
    CHECK(detail::invalid_utf8_at("ok\x80") == 2);              // a stray continuation byte
    CHECK(detail::invalid_utf8_at("ok\xE2\x82") == 2);          // truncated at the end
    CHECK(detail::invalid_utf8_at("ok\xE2\x82x") == 2);         // truncated inside
    CHECK(detail::invalid_utf8_at("Fahrzeug \xAB" "A\xBB") == 9);  // Latin-1 guillemets
    CHECK(detail::invalid_utf8_at("Fahrzeug \xC2\xAB" "A\xC2\xBB") == std::string::npos);
    CHECK(detail::utf8_replaced("a\xAB" "b") == "a\xEF\xBF\xBD" "b");
}

TEST_CASE("a text that is not UTF-8 is refused naming its line and its byte in that line") {
    CHECK_NOTHROW(detail::require_utf8("name,k1\nZo\xC3\xAB,1\n", "cars.csv"));
    CHECK_THROWS_WITH_AS(detail::require_utf8("name,k1\nZo\xEB,1\n", "cars.csv"),
                         "cars.csv:2: byte 3 (0xEB) is not UTF-8: expected UTF-8 text", std::invalid_argument);
    CHECK_THROWS_WITH_AS(detail::require_utf8("\xFF", "x.csv"), "x.csv:1: byte 1 (0xFF) is not UTF-8: expected UTF-8 text", std::invalid_argument);
    CHECK_THROWS_WITH_AS(detail::CsvReader("name,k1\n\xE9t\xE9,1\n", "c.csv", "name,k1"), doctest::Contains("c.csv:2: byte 1 (0xE9)"),
                         std::invalid_argument);
}

TEST_CASE("writers: a CSV field with a separator or a quote or a line end or a leading hash is quoted and bytes that are not UTF-8 become U+FFFD") {
    CHECK(csv_field("plain") == "plain");
    CHECK(csv_field("a,b") == "\"a,b\"");
    CHECK(csv_field("say \"hi\"") == "\"say \"\"hi\"\"\"");
    CHECK(csv_field("#1") == "\"#1\"");
    CHECK(csv_field("x\xAB") == "x\xEF\xBF\xBD");
    // what the reader makes of it is the name again
    const auto fields = detail::split_csv_line(csv_field("a, \"b\"") + ",2");
    REQUIRE(fields.size() == 2);
    CHECK(fields[0] == "a, \"b\"");
}
