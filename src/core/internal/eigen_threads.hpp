#pragma once
/// \file eigen_threads.hpp
/// Eigen's dense products in one thread for the lifetime of the guard. Used where the matrices
/// are too small for OpenMP's threads: on a loaded machine those spent several times the work in
/// waiting (BENCHMARKS.md, periodic orbits and large sparse systems). The previous setting is
/// restored.

#include <Eigen/Core>

namespace ddemap {

struct SingleThreadedEigen {
    int previous = Eigen::nbThreads();
    SingleThreadedEigen() { Eigen::setNbThreads(1); }
    ~SingleThreadedEigen() { Eigen::setNbThreads(previous); }
    SingleThreadedEigen(const SingleThreadedEigen&) = delete;
    SingleThreadedEigen& operator=(const SingleThreadedEigen&) = delete;
};

}  // namespace ddemap
