#pragma once
// Internal text helpers shared by the readers and the error messages of the library.
#include <string>
#include <vector>

namespace ddemap::detail {

/// The shortest of %.15g, %.16g, %.17g that reads back to the same double (for messages).
std::string format_number(double v);

/// Splits one CSV line: commas, double-quoted fields ("" for a quote), fields trimmed of
/// blanks and carriage returns.
std::vector<std::string> split_csv_line(const std::string& line);

/// Parses a whole field as a finite double (no trailing characters, no overflow).
bool parse_finite(const std::string& text, double& value);

/// True for an empty or all-blank line.
bool is_blank(const std::string& line);

}  // namespace ddemap::detail
