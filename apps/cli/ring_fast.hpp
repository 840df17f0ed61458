#pragma once
// --ring-method of roots and string (the ring of identical cars: analysis/ring_fast.hpp).
#include <string>

namespace ddemap::cli {

/// --ring-method TEXT: auto, winding or modes (BadInput otherwise).
std::string parse_ring_method(const std::string& text);

}  // namespace ddemap::cli
