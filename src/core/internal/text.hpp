#pragma once
// Internal text helpers shared by the readers and the error messages of the library (private:
// not installed; the layers include it as "core/internal/text.hpp").
#include <string>
#include <utility>
#include <vector>

namespace ddemap::detail {

/// The shortest of %.15g, %.16g, %.17g that reads back to the same double (for messages).
std::string format_number(double v);

/// std::invalid_argument "NAME = VALUE: expected EXPECTED" unless `ok` (a model's parameter check).
void require_value(bool ok, const char* name, double value, const char* expected);

/// v with `digits` significant digits (%g style: "1.49", "6.9e-10"), for human messages.
std::string significant(double v, int digits);

/// Input text for an error message: in single quotes, control characters escaped (\n, \r,
/// \t, \xNN) so that a message stays one line, and cut to 80 characters ("...").
std::string quoted(const std::string& text);

/// The same without the quotes, cut to `max_chars`: for a third-party message that may echo
/// input (a parser's error description).
std::string escaped(const std::string& text, std::size_t max_chars = 200);

/// The offset of the first byte of `text` (from `from` on) that is not part of well-formed
/// UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF, no truncated
/// sequence), or std::string::npos when all of it is.
std::size_t invalid_utf8_at(const std::string& text, std::size_t from = 0);

/// `text` with every byte that is not part of well-formed UTF-8 replaced by U+FFFD (for
/// writers that must emit UTF-8 whatever they are given, e.g. a path in a JSON string).
std::string utf8_replaced(const std::string& text);

/// Throws std::invalid_argument "SOURCE:LINE: byte K (0xNN) is not UTF-8: expected UTF-8 text"
/// (K counted from 1 within the line) when `text` is not well-formed UTF-8.
void require_utf8(const std::string& text, const std::string& source);

/// Splits one CSV line: commas, double-quoted fields ("" for a quote), fields trimmed of
/// blanks and carriage returns.
std::vector<std::string> split_csv_line(const std::string& line);

/// Parses a whole field as a finite double (no trailing characters, no overflow).
bool parse_finite(const std::string& text, double& value);

/// True when `text` holds a control character (below 0x20, or 0x7f): refused in names, which
/// go into messages, CSV rows and figure labels.
bool has_control(const std::string& text);

/// True for an empty or all-blank line.
bool is_blank(const std::string& line);
/// `s` without leading and trailing spaces, tabs and line ends.
std::string trim(const std::string& s);

/// A CSV text with a header line; blank lines and lines starting with '#' are skipped. Errors
/// are std::invalid_argument starting with "SOURCE:LINE: ". The text must be UTF-8 (every
/// reader of names takes them through here): a byte that is not is refused naming its line and
/// its byte within the line (require_utf8).
class CsvReader {
public:
    /// `expected` describes the columns for messages, e.g. "name,k1,k2,th,tau[,eta]".
    CsvReader(const std::string& text, std::string source, std::string expected);
    /// Index of a column; -1 if absent and not required; required and absent: an error.
    int column(const std::string& name, bool required = true) const;
    int columns() const { return static_cast<int>(m_header.size()); }
    /// A hint for a header column that is not expected: "; the header is separated by ';' ..."
    /// (or tabs), "; column names are lower case: 'name'" when its lower case is one of `known`,
    /// else empty.
    std::string header_hint(const std::string& column, const std::vector<std::string>& known) const;
    const std::vector<std::string>& header() const { return m_header; }
    /// Gives header column `index` the name `name` (a reader's canonical spelling of a column
    /// that a file may write in another, e.g. with its unit: `k1_per_s2` -> `k1`).
    void rename_column(int index, std::string name) { m_header.at(static_cast<std::size_t>(index)) = std::move(name); }
    /// Advances to the next data row; false at the end.
    bool next();
    /// "SOURCE:LINE" of the current row.
    std::string where() const;
    const std::vector<std::string>& fields() const { return m_fields; }
    /// The current row's field as a finite number ("column 'NAME' = 'X': expected a finite number").
    double number(int column, const std::string& name) const;
    /// Throws "SOURCE:LINE: what" for the current row.
    [[noreturn]] void fail(const std::string& what) const;

private:
    std::vector<std::string> m_lines;
    std::string m_source, m_expected;
    std::vector<std::string> m_header, m_fields;
    std::size_t m_pos = 0;
    int m_header_line = 0, m_line = 0;
};

}  // namespace ddemap::detail
