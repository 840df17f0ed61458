// The precompiled header of ddemap's targets (cmake/DdemapPch.cmake): the standard and Eigen
// headers that nearly every file includes, parsed once per target instead of once per file, and
// the declarations of the dense decompositions compiled once (src/core/internal/eigen_instances.hpp).
// Only a build-time cache: every file still includes what it uses.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "../src/core/internal/eigen_instances.hpp"
