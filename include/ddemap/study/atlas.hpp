#pragma once
/// \file atlas.hpp
/// Atlases: the sweep's quantities and verdicts on a grid over up to five model parameters and a
/// list of ring sizes. The grid is flattened in C order with the ring size outermost and the last
/// parameter axis innermost, and cut into fixed chunks of consecutive points. A chunk is the unit
/// of work (of a thread, of an MPI rank, of a resumed run): along a chunk the ring's certificate
/// (winding tables or per-mode roots, AtlasSpec::ring_method) and the plant's root are continued
/// from point to point exactly as along a sweep row, starting afresh at the chunk's first point
/// and whenever the ring size changes.
/// The values of a point thus depend only on the spec (its chunk), never on which process or
/// thread computed it or in which order: an atlas is bitwise the same for any schedule.

#include <string>
#include <vector>

#include "ddemap/study/sweep.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

/// One parameter axis of an atlas: explicit values, or `count` values from lo to hi inclusive
/// (lo + (hi - lo) i / (count - 1), the sweep's Axis::value, so the coordinates agree bitwise
/// with a sweep over the same range).
struct AtlasAxis {
    std::string name;
    std::vector<double> values;
    bool uniform = false;  ///< given as lo, hi, count
    double lo = 0.0, hi = 0.0;  ///< uniform axes: the range as given (values.back() may differ from hi by rounding)
    /// The axis as a sweep axis (uniform axes only).
    Axis sweep_axis() const;
};

struct AtlasSpec {
    std::string title;
    std::string model = "ovrv";
    ParameterMap fixed;            ///< the parameters that are not swept
    std::vector<AtlasAxis> axes;   ///< 2 to 5 axes, outer to inner
    std::vector<int> rings{22};    ///< ring sizes N >= 2, 0 = infinity
    long chunk = 0;                ///< points per chunk; 0: the innermost axis's length
    /// The ring certificate, as a sweep's (SweepSpec::ring_method): "winding" (every mode from
    /// winding tables, cost independent of N, rings up to kWindingMaxCars; one-leader laws),
    /// "modes" (each mode's rightmost root continued and certified: cost ~ N, rings up to
    /// kModesMaxCars) or "auto" (winding when it applies).
    std::string ring_method = "auto";

    /// Throws std::invalid_argument naming the field: axis count, repeated or fixed-and-swept
    /// names, empty or non-finite axes, bad ring sizes (N above kWindingMaxCars, or above
    /// kModesMaxCars on the per-mode path), an unknown ring method or "winding" for a law with
    /// more than one leader, and a model that cannot be built (or is outside the computable
    /// range) at any corner of the grid.
    void validate() const;
    /// "winding" or "modes": the method ring_method resolves to for this model (decided at the
    /// first point of the grid, as a sweep decides at its first corner).
    std::string ring_method_used() const;
    /// rings.size() x the axes' lengths (the datasets' shape).
    std::vector<long> shape() const;
    long points() const;       ///< product of shape()
    long chunk_size() const;   ///< chunk, or the innermost axis's length
    long chunks() const;       ///< ceil(points / chunk_size)
    /// The first point of chunk c and one past its last.
    long chunk_begin(long c) const { return c * chunk_size(); }
    long chunk_end(long c) const;
    /// The ring size and parameter values of flat point `index`.
    int ring_at(long index) const;
    ParameterMap parameters_at(long index) const;
};

/// The quantities stored per point, in this order (every one a double in a chunk's values;
/// integers and flags are exact): the sweep's SweepPoint fields.
struct AtlasField {
    const char* name;
    char type;  ///< 'f' float64, 'i' int32, 'b' flag (uint8, 0 or 1)
    const char* description;
};
const std::vector<AtlasField>& atlas_fields();

/// The values of chunk `c`: (chunk_end - chunk_begin) x atlas_fields().size(), point-major.
/// Deterministic: the same bits whenever and wherever it is computed. The ring part comes from
/// ring_method_used(): on the winding path (detail::winding_ring_summary, as a sweep's winding
/// rows) the continuation data of the winding tables start empty at the chunk's first point and
/// at each new ring size; an undecided point falls back to the per-mode path for
/// N <= kWindingFallbackCars (N = inf included) and is stored uncertified above.
std::vector<double> evaluate_atlas_chunk(const AtlasSpec& spec, long c);

/// A point's values as the sweep's point (x, y: the last two axes' values are not stored; the
/// caller sets them).
SweepPoint atlas_point(const double* values);

/// FNV-1a 64-bit hash of bytes (fingerprints of specs and chunk records).
unsigned long long fnv1a64(const void* data, std::size_t size, unsigned long long seed = 14695981039346656037ull);

}  // namespace ddemap
