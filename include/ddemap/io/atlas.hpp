#pragma once
/// \file atlas.hpp
/// Atlas files: the spec (TOML, see maps/atlas-example.toml), the chunk store that lets an
/// interrupted atlas resume, the HDF5 result and the small-multiples figure.

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "ddemap/study/atlas.hpp"

namespace ddemap {

/// An atlas spec and its figure layout.
struct AtlasFile {
    AtlasSpec spec;
    int columns = 0;  ///< panels per row of the figure; 0: the length of the last outer axis (at most 6)
};

/// Parses an atlas spec:
///     title = "..."            (optional)
///     model = "ovrv"           (optional, default ovrv)
///     rings = [22, "inf"]      (ring sizes, integers from 2 to 1e9 or "inf"; default [22])
///     chunk = 24               (optional: points per chunk, 1 to 1e6; default the last axis's count)
///     columns = 4              (optional: figure panels per row, 1 to 64)
///     [fixed]                  parameters that are not swept
///     [[axis]]                 2 to 5 swept parameters, outer to inner, each with
///     name = "tau"             and either values = [..] or lo, hi, count (2 to 100000);
///                              the last two axes (the figure's plane) with lo, hi, count.
/// Unknown keys, non-finite numbers, integers that are not TOML integers in range: one-line
/// std::invalid_argument naming `source`, the line and the key. The spec is validated
/// (AtlasSpec::validate), with `source` named.
AtlasFile parse_atlas_spec(const std::string& text, const std::string& source);

/// The fingerprint of a run: FNV-1a of the ddemap version and the spec's exact text. A chunk
/// store is resumed only by a run with the same fingerprint.
unsigned long long atlas_fingerprint(const std::string& spec_text);

/// Fills `out` with the values of finished chunk `c` (chunk_end - chunk_begin points x
/// atlas_fields().size(), point-major): how the writers below get the values, one chunk at a
/// time, so that an atlas of any size is written in bounded memory.
using AtlasChunkReader = std::function<void(long c, double* out)>;

/// The chunk store of an atlas run (DIR/atlas.chunks): a header (format, fingerprint, points,
/// chunk size) and one record per finished chunk (chunk index, value count, the values as
/// native doubles, FNV-1a checksum), each appended with one write() as the chunk finishes (it
/// then survives the process: Ctrl-C, kill -9, a lost MPI rank) and fdatasync()ed at most once
/// per `sync_interval` seconds and on close (so that a crash of the machine loses at most that
/// last interval, and the disk's latency never paces the work). A run killed at any moment
/// leaves a store whose complete records are valid; a torn last record fails its length or
/// checksum test and is dropped on resume. The values stay in the file: the store keeps only
/// an index (8 bytes per chunk), and read() gets a chunk back.
class AtlasStore {
public:
    /// Opens `path`. Without `resume` (or with no store at `path`) the store starts empty (an
    /// old one is truncated). With `resume`, every complete record is checked (length,
    /// checksum), indexed and marked in `done` (one flag per chunk); the file is cut after the
    /// last complete record. std::invalid_argument when the store belongs to another spec
    /// (fingerprint, size or chunking differ) or is not a chunk store; WriteError when it
    /// cannot be opened or written.
    AtlasStore(const std::string& path, const AtlasSpec& spec, unsigned long long fingerprint, bool resume, std::vector<char>& done);
    ~AtlasStore();
    AtlasStore(const AtlasStore&) = delete;
    AtlasStore& operator=(const AtlasStore&) = delete;

    long loaded() const { return m_loaded; }          ///< chunks read back on resume
    long dropped_bytes() const { return m_dropped; }  ///< bytes of a torn last record cut off
    /// Appends chunk `c` (its values: count doubles); WriteError on failure,
    /// std::invalid_argument for a chunk outside the atlas or already stored.
    /// Not thread-safe (callers serialise).
    void append(long c, const double* values, std::size_t count);
    /// The values of stored chunk `c` into `out` (pread; std::invalid_argument for a chunk not
    /// stored, std::runtime_error when the file cannot be read). Not concurrent with append.
    void read(long c, double* out) const;
    /// read() as an AtlasChunkReader (valid while the store lives).
    AtlasChunkReader reader() const;
    /// fdatasync now (WriteError on failure).
    void sync();
    /// Seconds between fdatasyncs of append (default 1; 0: after every chunk).
    void set_sync_interval(double seconds) { m_sync_interval = seconds; }

private:
    std::string m_path;
    AtlasSpec m_spec;
    int m_fd = -1;
    long m_loaded = 0, m_dropped = 0;
    std::vector<long long> m_offset;  ///< per chunk: the file offset of its values, -1 when not stored
    long long m_end = 0;              ///< the end of the last complete record
    double m_sync_interval = 1.0;
    std::chrono::steady_clock::time_point m_synced;
};

/// The HDF5 file: one dataset per atlas field shaped like the grid (ring, axes...; float64,
/// int32 or uint8 flags; contiguous; attributes "description" and "dimensions"), the coordinate
/// arrays in /coordinates (ring: int32, 0 = infinity; one float64 array per axis), and root
/// attributes "spec" (the spec's text), "version", "model", "ring_method" (the method used),
/// "dimensions", "points" and "chunk_size". No timestamps are stored: the same values give the
/// same bytes. Written to `path`.part in slabs: flat ranges of at most `slab_points` points
/// that are hyperslabs of the grid, each read chunk by chunk through `read` (every chunk must be
/// finished); memory: one slab (slab_points x 16 doubles and one field's copy) and one chunk,
/// whatever the atlas's size. Then fsynced and renamed to `path` (an old file is replaced
/// whole, never half written). WriteError when the file cannot be created or written (the
/// .part file is removed).
void write_atlas_hdf5(const std::string& path, const AtlasSpec& spec, const AtlasChunkReader& read, const std::string& spec_text,
                      long slab_points = 65536);

/// The same file as bytes, built in memory from every point's values (points x fields,
/// point-major): for small atlases and tests.
std::string atlas_hdf5(const AtlasSpec& spec, const std::vector<double>& values, const std::string& spec_text);

/// True when `path` is an atlas HDF5 file written by this ddemap version for exactly
/// `spec_text` (its "spec" and "version" attributes); false for anything else, a missing or
/// unreadable file included.
bool atlas_hdf5_matches(const std::string& path, const std::string& spec_text);

/// At most this many panels in an atlas's figure (the first ones, in the grid's order).
constexpr long kAtlasFigurePanels = 256;

/// Small multiples: the verdict map in the plane of the last two axes for every ring size and
/// combination of the outer axes (render_chart_svg), read chunk by chunk through `read`. At
/// most kAtlasFigurePanels panels, and in each every s-th point of both axes of the plane,
/// s >= 1 the smallest with at most `budget` points in all panels; the title says when the
/// figure shows fewer panels or points than the atlas holds.
std::string atlas_svg(const AtlasFile& file, const AtlasChunkReader& read, long budget = 250000);
/// The same from every point's values (points x fields, point-major).
std::string atlas_svg(const AtlasFile& file, const std::vector<double>& values);

}  // namespace ddemap
