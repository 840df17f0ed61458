#pragma once
/// \file newton.hpp
/// The one Newton loop lives in core/newton.hpp (so that problem/ may use it too); this header
/// is kept for the solve/ include path.
#include "ddemap/core/newton.hpp"
