// The definitions of one group of core/internal/eigen_instances.hpp (see there).
#define DDEMAP_EIGEN_INSTANTIATE_EIG
#include "core/internal/eigen_instances.hpp"
