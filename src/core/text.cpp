#include <cctype>
#include "core/internal/text.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace ddemap::detail {

std::string escaped(const std::string& text, std::size_t max_chars) {
    // bytes that are not part of valid UTF-8 are shown as \xNN too: a message stays valid text
    std::vector<bool> invalid(text.size(), false);
    for (std::size_t i = invalid_utf8_at(text, 0); i < text.size(); i = invalid_utf8_at(text, i + 1)) invalid[i] = true;
    std::string out;
    std::size_t shown = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char ch = text[i];
        if (shown >= max_chars) {
            out += "...";
            break;
        }
        const auto c = static_cast<unsigned char>(ch);
        if (c == '\n') out += "\\n";
        else if (c == '\r') out += "\\r";
        else if (c == '\t') out += "\\t";
        else if (c < 0x20 || c == 0x7f || invalid[i]) {
            static const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += ch;
        }
        ++shown;
    }
    return out;
}

bool has_control(const std::string& text) {
    for (const char ch : text) {
        const auto c = static_cast<unsigned char>(ch);
        if (c < 0x20 || c == 0x7f) return true;
    }
    return false;
}

std::string quoted(const std::string& text) { return "'" + escaped(text, 80) + "'"; }

void require_value(bool ok, const char* name, double value, const char* expected) {
    if (!ok) throw std::invalid_argument(std::string(name) + " = " + format_number(value) + ": expected " + expected);
}

std::string format_number(double v) {
    char buf[40];
    for (int p = 15; p <= 17; ++p) {
        std::snprintf(buf, sizeof buf, "%.*g", p, v);
        if (std::strtod(buf, nullptr) == v) break;
    }
    return buf;
}

std::string significant(double v, int digits) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

std::size_t invalid_utf8_at(const std::string& text, std::size_t from) {
    const std::size_t n = text.size();
    std::size_t i = from;
    while (i < n) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c < 0x80) {
            ++i;
            continue;
        }
        int len = 0;
        unsigned lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
        if (c >= 0xC2 && c <= 0xDF) len = 2;
        else if (c == 0xE0) len = 3, lo = 0xA0;
        else if (c >= 0xE1 && c <= 0xEC) len = 3;
        else if (c == 0xED) len = 3, hi = 0x9F;  // no surrogates
        else if (c >= 0xEE && c <= 0xEF) len = 3;
        else if (c == 0xF0) len = 4, lo = 0x90;
        else if (c >= 0xF1 && c <= 0xF3) len = 4;
        else if (c == 0xF4) len = 4, hi = 0x8F;  // at most U+10FFFF
        else return i;
        if (i + static_cast<std::size_t>(len) > n) return i;
        const auto c1 = static_cast<unsigned char>(text[i + 1]);
        if (c1 < lo || c1 > hi) return i;
        for (int k = 2; k < len; ++k) {
            const auto ck = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
            if (ck < 0x80 || ck > 0xBF) return i;
        }
        i += static_cast<std::size_t>(len);
    }
    return std::string::npos;
}

std::string utf8_replaced(const std::string& text) {
    std::size_t bad = invalid_utf8_at(text);
    if (bad == std::string::npos) return text;
    std::string out;
    std::size_t from = 0;
    while (bad != std::string::npos) {
        out.append(text, from, bad - from);
        out += "\xEF\xBF\xBD";  // U+FFFD
        from = bad + 1;
        bad = invalid_utf8_at(text, from);
    }
    out.append(text, from, std::string::npos);
    return out;
}

void require_utf8(const std::string& text, const std::string& source) {
    const std::size_t bad = invalid_utf8_at(text);
    if (bad == std::string::npos) return;
    const std::size_t line_start = bad == 0 ? 0 : text.rfind('\n', bad - 1);
    const std::size_t column = line_start == std::string::npos ? bad + 1 : (bad == 0 ? 1 : bad - line_start);
    long line = 1;
    for (std::size_t i = 0; i < bad; ++i) line += text[i] == '\n';
    static const char* hex = "0123456789ABCDEF";
    const auto c = static_cast<unsigned char>(text[bad]);
    throw std::invalid_argument(source + ":" + std::to_string(line) + ": byte " + std::to_string(column) + " (0x" + hex[c >> 4] + hex[c & 15] +
                                ") is not UTF-8: expected UTF-8 text");
}

std::vector<std::string> split_csv_line(const std::string& line) {
    std::vector<std::string> out;
    std::string field;
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted) {
            if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                field += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                field += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            out.push_back(field);
            field.clear();
        } else if (c != '\r') {
            field += c;
        }
    }
    out.push_back(field);
    for (auto& f : out) {
        const auto b = f.find_first_not_of(" \t");
        const auto e = f.find_last_not_of(" \t");
        f = b == std::string::npos ? std::string() : f.substr(b, e - b + 1);
    }
    return out;
}

bool parse_finite(const std::string& text, double& value) {
    if (text.empty()) return false;
    char* end = nullptr;
    errno = 0;
    value = std::strtod(text.c_str(), &end);
    // ERANGE is overflow (+-HUGE_VAL: not finite) or underflow (1e-310: a subnormal or 0, a finite
    // number that the value's own range check judges)
    const bool underflow = errno == ERANGE && std::abs(value) <= std::numeric_limits<double>::min();
    return *end == '\0' && (errno != ERANGE || underflow) && std::isfinite(value);
}

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return "";
    const auto e = s.find_last_not_of(" \t\r\n");
    return s.substr(b, e - b + 1);
}

bool is_blank(const std::string& line) { return line.find_first_not_of(" \t\r") == std::string::npos; }

CsvReader::CsvReader(const std::string& text, std::string source, std::string expected)
    : m_source(std::move(source)), m_expected(std::move(expected)) {
    require_utf8(text, m_source);
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) m_lines.push_back(line);
    while (m_pos < m_lines.size()) {
        const std::string& l = m_lines[m_pos++];
        if (is_blank(l) || l[0] == '#') continue;
        m_header = split_csv_line(l);
        m_header_line = static_cast<int>(m_pos);
        break;
    }
    if (m_header.empty()) throw std::invalid_argument(m_source + ": empty file: expected a header " + m_expected);
    const std::string& header_line = m_lines[static_cast<std::size_t>(m_header_line - 1)];
    const std::size_t at = header_line.find_first_not_of(" \t\r\xEF\xBB\xBF");  // spaces and a byte-order mark
    if (at != std::string::npos && (header_line[at] == '{' || header_line[at] == '['))
        throw std::invalid_argument(m_source + " is JSON: expected a CSV file with a header " + m_expected);
}

std::string CsvReader::header_hint(const std::string& column, const std::vector<std::string>& known) const {
    if (column.find(';') != std::string::npos)
        return "; the header is separated by ';': expected commas (export the file as CSV with ',' as the separator and '.' as the decimal point)";
    if (column.find('\t') != std::string::npos) return "; the header is separated by tabs: expected commas";
    std::string lower = column;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (lower != column && std::find(known.begin(), known.end(), lower) != known.end())
        return "; column names are lower case: " + quoted(lower);
    return "";
}

int CsvReader::column(const std::string& name, bool required) const {
    for (std::size_t i = 0; i < m_header.size(); ++i)
        if (m_header[i] == name) return static_cast<int>(i);
    if (required) {
        std::string hint;
        for (const std::string& h : m_header) {
            std::string lower = h;
            for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            if (lower == name) hint = "; the header has " + quoted(h) + ": column names are lower case";
        }
        if (hint.empty() && m_header.size() == 1 && m_header[0].find(';') != std::string::npos)
            hint = "; the header is separated by ';': expected commas (export the file as CSV with ',' as the separator and '.' as the decimal point)";
        else if (hint.empty() && m_header.size() == 1 && m_header[0].find('\t') != std::string::npos)
            hint = "; the header is separated by tabs: expected commas";
        throw std::invalid_argument(m_source + ":" + std::to_string(m_header_line) + ": missing column " + quoted(name) + " (expected " +
                                    m_expected + ")" + hint);
    }
    return -1;
}

bool CsvReader::next() {
    while (m_pos < m_lines.size()) {
        const std::string& l = m_lines[m_pos++];
        if (is_blank(l) || l[0] == '#') continue;
        m_fields = split_csv_line(l);
        m_line = static_cast<int>(m_pos);
        if (m_fields.size() != m_header.size()) {
            fail(std::to_string(m_fields.size()) + " fields, expected " + std::to_string(m_header.size()) + " as in the header");
        }
        return true;
    }
    return false;
}

std::string CsvReader::where() const { return m_source + ":" + std::to_string(m_line); }

double CsvReader::number(int column, const std::string& name) const {
    const std::string& x = m_fields.at(static_cast<std::size_t>(column));
    double v = 0.0;
    if (!parse_finite(x, v)) fail("column " + quoted(name) + " = " + quoted(x) + ": expected a finite number");
    return v;
}

void CsvReader::fail(const std::string& what) const { throw std::invalid_argument(where() + ": " + what); }

}  // namespace ddemap::detail
