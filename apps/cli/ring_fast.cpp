#include "ring_fast.hpp"

#include "common.hpp"

namespace ddemap::cli {

std::string parse_ring_method(const std::string& text) {
    if (text == "auto" || text == "winding" || text == "modes") return text;
    throw BadInput("--ring-method = '" + text + "': expected auto, winding or modes");
}

}  // namespace ddemap::cli
