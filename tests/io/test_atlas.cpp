#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "ddemap/io/atlas.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/study/sweep.hpp"
#include "temp_dir.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using ddemap::test::TempDir;
namespace fs = std::filesystem;

namespace {

const char* good_spec = R"(title = "t"
model = "ovrv"
rings = [22, "inf"]
chunk = 5
[fixed]
eta = 10.0
[[axis]]
name = "tau"
values = [0.1, 0.4]
[[axis]]
name = "th"
values = [1.0, 2.0, 1.5]
[[axis]]
name = "k1"
lo = 0.01
hi = 1.0
count = 4
[[axis]]
name = "k2"
lo = 0.01
hi = 1.0
count = 3
)";

/// `good_spec` with `from` replaced by `to` (which must occur).
std::string edited(const std::string& from, const std::string& to) {
    std::string s = good_spec;
    const auto at = s.find(from);
    REQUIRE(at != std::string::npos);
    return s.replace(at, from.size(), to);
}

/// The parser's message for `text` (empty when it parses).
std::string error_of(const std::string& text) {
    try {
        parse_atlas_spec(text, "a.toml");
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}


}  // namespace

TEST_CASE("atlas spec: a good spec gives the grid, the rings and the chunks") {
    const AtlasFile f = parse_atlas_spec(good_spec, "a.toml");
    const AtlasSpec& s = f.spec;
    CHECK(s.rings == std::vector<int>{22, 0});
    CHECK(s.shape() == std::vector<long>{2, 2, 3, 4, 3});
    CHECK(s.points() == 144);
    CHECK(s.chunk_size() == 5);
    CHECK(s.chunks() == 29);  // ceil(144 / 5)
    Axis k1;
    k1.lo = 0.01;
    k1.hi = 1.0;
    k1.count = 4;
    for (int i = 0; i < 4; ++i) CHECK(s.axes[2].values[static_cast<std::size_t>(i)] == k1.value(i));  // the sweep's coordinates, bitwise
    CHECK(s.axes[1].values == std::vector<double>{1.0, 2.0, 1.5});
    // C order: ring outermost, the last axis fastest
    const ParameterMap p = s.parameters_at(1 * 72 + 1 * 36 + 2 * 12 + 3 * 3 + 2);
    CHECK(s.ring_at(1 * 72) == 0);
    CHECK(s.ring_at(71) == 22);
    CHECK(p.at("tau") == 0.4);
    CHECK(p.at("th") == 1.5);
    CHECK(p.at("k1") == k1.value(3));
    CHECK(p.at("k2") == s.axes[3].values[2]);
    CHECK(p.at("eta") == 10.0);
    // without chunk: one row of the innermost axis per chunk
    const AtlasFile g = parse_atlas_spec(edited("chunk = 5\n", ""), "a.toml");
    CHECK(g.spec.chunk_size() == 3);
    CHECK(g.spec.chunks() == 48);
}

TEST_CASE("atlas spec: bad inputs are refused in one line naming the key and the line") {
    struct Bad {
        std::string from, to, expect;
    };
    const Bad cases[] = {
        {"chunk = 5", "chunks = 5", "a.toml:4: unknown key 'chunks'"},
        {"chunk = 5", "chunk = 5.0", "a.toml:4: chunk: expected an integer"},
        {"chunk = 5", "chunk = 0", "a.toml:4: chunk: expected an integer"},
        {"chunk = 5", "chunk = 1e308", "a.toml:4: chunk: expected an integer"},
        {"count = 4", "count = 4.0", "axis[3]: expected lo < hi and an integer count"},
        {"count = 4", "count = 9223372036854775807", "expected lo < hi and an integer count"},
        {"count = 4", "count = 1", "expected lo < hi and an integer count"},
        {"lo = 0.01\nhi = 1.0\ncount = 4", "lo = nan\nhi = 1.0\ncount = 4", "axis[3].lo: expected a finite number"},
        {"lo = 0.01\nhi = 1.0\ncount = 4", "lo = 0.01\nhi = inf\ncount = 4", "axis[3].hi: expected a finite number"},
        {"lo = 0.01\nhi = 1.0\ncount = 4", "lo = 1.0\nhi = 0.01\ncount = 4", "expected lo < hi"},
        {"rings = [22, \"inf\"]", "rings = [1]", "a.toml:3: rings: expected integers N from 2"},
        {"rings = [22, \"inf\"]", "rings = [\"infinity\"]", "rings: expected integers N from 2"},
        {"rings = [22, \"inf\"]", "rings = [22, 22]", "a ring size is repeated"},
        {"rings = [22, \"inf\"]", "rings = []", "rings: expected an array of 1 to 64"},
        {"values = [0.1, 0.4]", "values = [0.1, 0.1]", "axis 'tau': a value is repeated"},
        {"values = [0.1, 0.4]", "values = [0.1, \"x\"]", "axis[1].values: expected a number"},
        {"values = [0.1, 0.4]", "values = 0.1", "axis[1].values: expected an array"},
        {"values = [0.1, 0.4]", "values = [0.1]\nlo = 0.0", "either values or lo, hi, count"},
        {"name = \"tau\"", "name = \"th\"", "parameter 'th' is swept twice"},
        {"name = \"tau\"", "name = \"eta\"", "parameter 'eta' is both swept and fixed"},
        {"name = \"tau\"", "nom = \"tau\"", "unknown key 'axis[1].nom'"},
        {"name = \"k2\"\nlo = 0.01\nhi = 1.0\ncount = 3", "name = \"k2\"\nvalues = [0.1, 0.2]", "the last two axes"},
        {"model = \"ovrv\"", "model = \"nope\"", "a.toml: "},
        {"eta = 10.0", "eta = 1e400", "a.toml:"},
        {"title = \"t\"", "title = \"t", "a.toml:1: "},
        {"lo = 0.01\nhi = 1.0\ncount = 4", "lo = 0.01\nhi = 500.0\ncount = 4", "computable"},
    };
    for (const auto& c : cases) {
        CAPTURE(c.to);
        const std::string e = error_of(edited(c.from, c.to));
        CHECK(e.find(c.expect) != std::string::npos);
        CHECK(e.find('\n') == std::string::npos);
    }
    // the number of axes: 2 to 5
    std::string one = good_spec;
    one = one.substr(0, one.find("[[axis]]")) + "[[axis]]\nname = \"k1\"\nlo = 0.1\nhi = 1.0\ncount = 3\n";
    CHECK(error_of(one).find("expected 2 to 5 swept parameters") != std::string::npos);
    const std::string six = edited("[[axis]]\nname = \"tau\"", "[[axis]]\nname = \"a1\"\nvalues = [1.0]\n[[axis]]\nname = \"a2\"\nvalues = [1.0]\n[[axis]]\nname = \"tau\"");
    CHECK(error_of(six).find("an atlas has 6 axes: expected 2 to 5 swept parameters") != std::string::npos);
    CHECK(error_of("[fixed]\neta = 10.0\n").find("[[axis]] tables missing") != std::string::npos);
}

TEST_CASE("atlas chunks: every point in exactly one chunk, and a chunk's values do not depend on when it is computed") {
    const AtlasSpec s = parse_atlas_spec(edited("chunk = 5", "chunk = 7"), "a.toml").spec;
    std::set<long> seen;
    for (long c = 0; c < s.chunks(); ++c)
        for (long i = s.chunk_begin(c); i < s.chunk_end(c); ++i) CHECK(seen.insert(i).second);
    CHECK(static_cast<long>(seen.size()) == s.points());
    CHECK(*seen.rbegin() == s.points() - 1);
    CHECK_THROWS_AS(evaluate_atlas_chunk(s, s.chunks()), std::invalid_argument);
    // chunk 3 alone, and after other chunks: the same bits (fresh continuation at the chunk start)
    const std::vector<double> a = evaluate_atlas_chunk(s, 3);
    evaluate_atlas_chunk(s, 10);
    const std::vector<double> b = evaluate_atlas_chunk(s, 3);
    REQUIRE(a.size() == b.size());
    CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
    CHECK(a.size() == 7 * atlas_fields().size());
}

TEST_CASE("atlas chunks: the points agree with a sweep over the same window (a second continuation path), on both ring methods") {
    // one (k1, k2) plane: tau = 0.1, th = 1, N = 22 and N = inf; chunks of 2 points (many fresh starts)
    for (const char* method : {"winding", "modes"}) {
        for (int cars : {22, 0}) {
            CAPTURE(method);
            CAPTURE(cars);
            AtlasSpec one = parse_atlas_spec(edited("values = [0.1, 0.4]", "values = [0.1]"), "a.toml").spec;
            one.axes[1].values = {1.0};
            one.rings = {cars};
            one.chunk = 2;
            one.ring_method = method;
            CHECK(one.ring_method_used() == method);
            SweepSpec sw;
            sw.model = "ovrv";
            sw.fixed = {{"eta", 10.0}, {"tau", 0.1}, {"th", 1.0}};
            sw.x = one.axes[2].sweep_axis();
            sw.y = one.axes[3].sweep_axis();
            sw.cars = cars;
            sw.ring_method = method;
            const SweepResult r = run_sweep(sw);
            REQUIRE(r.ring_method == method);
            const std::size_t nf = atlas_fields().size();
            for (long c = 0; c < one.chunks(); ++c) {
                const std::vector<double> v = evaluate_atlas_chunk(one, c);
                for (long i = one.chunk_begin(c); i < one.chunk_end(c); ++i) {
                    const SweepPoint p = atlas_point(&v[static_cast<std::size_t>(i - one.chunk_begin(c)) * nf]);
                    const int ix = static_cast<int>(i / sw.y.count), iy = static_cast<int>(i % sw.y.count);
                    const SweepPoint& q = r.at(ix, iy);
                    CAPTURE(i);
                    CHECK(p.ring_stable == q.ring_stable);
                    CHECK(p.string_stable == q.string_stable);
                    CHECK(p.plant_stable == q.plant_stable);
                    CHECK(p.certified == q.certified);
                    CHECK(p.unstable_roots == q.unstable_roots);
                    CHECK(p.abscissa_mode == q.abscissa_mode);
                    CHECK(std::abs(p.spectral_abscissa - q.spectral_abscissa) <= test::tol::same_root);
                    CHECK(std::abs(p.sup_gamma - q.sup_gamma) <= test::tol::reference_sup_rel * q.sup_gamma);
                }
            }
        }
    }
}

TEST_CASE("atlas spec: the ring method, and rings up to the winding path's limit") {
    CHECK(parse_atlas_spec(good_spec, "a.toml").spec.ring_method == "auto");
    CHECK(parse_atlas_spec(good_spec, "a.toml").spec.ring_method_used() == "winding");  // OVRV reacts to the car ahead only
    CHECK(parse_atlas_spec(edited("chunk = 5", "chunk = 5\nring_method = \"modes\""), "a.toml").spec.ring_method_used() == "modes");
    CHECK(error_of(edited("chunk = 5", "chunk = 5\nring_method = \"fast\"")).find("a.toml:5: ring_method: expected \"auto\", \"winding\" or \"modes\"") !=
          std::string::npos);
    const AtlasFile big = parse_atlas_spec(edited("rings = [22, \"inf\"]", "rings = [1000000000, \"inf\"]"), "a.toml");
    CHECK(big.spec.rings == std::vector<int>{1000000000, 0});
    CHECK(error_of(edited("rings = [22, \"inf\"]", "rings = [1000000001]")).find("rings: expected integers N from 2 to 1e9") != std::string::npos);
    // the per-mode path solves N/2 + 1 modes per point: at most kModesMaxCars
    CHECK(error_of(edited("chunk = 5", "chunk = 5\nring_method = \"modes\"")).empty());
    const std::string modes_big = edited("rings = [22, \"inf\"]", "rings = [2000000]\nring_method = \"modes\"");
    CHECK(error_of(modes_big).find("expected at most 1000000 cars on the per-mode ring path") != std::string::npos);
    // a ring of 10^9 cars on the winding path: a chunk costs what N = 22 costs, and a point agrees with its sweep
    AtlasSpec s = big.spec;
    s.rings = {1000000000};
    s.axes[0].values = {0.4};
    s.axes[1].values = {1.0};
    s.chunk = 3;
    const std::vector<double> v = evaluate_atlas_chunk(s, 1);
    SweepSpec sw;
    sw.model = "ovrv";
    sw.fixed = {{"eta", 10.0}, {"tau", 0.4}, {"th", 1.0}};
    sw.x = s.axes[2].sweep_axis();
    sw.y = s.axes[3].sweep_axis();
    sw.cars = 1000000000;
    const SweepResult r = run_sweep(sw);
    const std::size_t nf = atlas_fields().size();
    for (long i = s.chunk_begin(1); i < s.chunk_end(1); ++i) {
        CAPTURE(i);
        const SweepPoint p = atlas_point(&v[static_cast<std::size_t>(i - s.chunk_begin(1)) * nf]);
        const SweepPoint& q = r.at(static_cast<int>(i / sw.y.count), static_cast<int>(i % sw.y.count));
        CHECK(p.ring_stable == q.ring_stable);
        CHECK(p.certified == q.certified);
        CHECK(p.unstable_roots == q.unstable_roots);
        CHECK(std::abs(p.spectral_abscissa - q.spectral_abscissa) <= test::tol::same_root);
    }
}

TEST_CASE("atlas store: finished chunks survive, a torn last record is dropped, another spec is refused") {
    TempDir dir;
    const std::string path = dir / "atlas.chunks";
    const AtlasSpec s = parse_atlas_spec(good_spec, "a.toml").spec;
    const std::size_t nf = atlas_fields().size();
    auto chunk_values = [&](long c) {
        std::vector<double> v(static_cast<std::size_t>(s.chunk_end(c) - s.chunk_begin(c)) * nf);
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<double>(c) + 1e-3 * static_cast<double>(i);
        return v;
    };
    std::vector<char> done;
    {
        AtlasStore st(path, s, 42, false, done);
        st.set_sync_interval(0);  // every chunk fdatasynced
        CHECK(st.loaded() == 0);
        for (long c : {3L, 0L, 28L}) {  // 28: the last, shorter chunk
            const auto v = chunk_values(c);
            st.append(c, v.data(), v.size());
        }
        CHECK_THROWS_AS(st.append(0, chunk_values(0).data(), chunk_values(0).size()), std::invalid_argument);  // twice
        std::vector<double> back(chunk_values(28).size());
        st.read(28, back.data());  // read back while it runs
        CHECK(back == chunk_values(28));
        CHECK_THROWS_AS(st.read(1, back.data()), std::invalid_argument);  // not stored
    }
    const auto full = fs::file_size(path);
    {
        AtlasStore st(path, s, 42, true, done);
        CHECK(st.loaded() == 3);
        CHECK(st.dropped_bytes() == 0);
        CHECK(done[0] == 1);
        CHECK(done[1] == 0);
        CHECK(done[3] == 1);
        CHECK(done[28] == 1);
        const auto v3 = chunk_values(3);
        std::vector<double> back(v3.size());
        st.read(3, back.data());
        CHECK(back == v3);
        CHECK_THROWS_AS(st.read(1, back.data()), std::invalid_argument);
    }
    // a run killed while writing its fourth record: half a record at the end
    {
        std::ofstream out(path, std::ios::binary | std::ios::app);
        const std::string half(1000, 'x');
        out << half;
    }
    {
        AtlasStore st(path, s, 42, true, done);
        CHECK(st.loaded() == 3);
        CHECK(st.dropped_bytes() == 1000);
        const auto v = chunk_values(7);
        st.append(7, v.data(), v.size());  // appended after the last complete record
    }
    {
        AtlasStore st(path, s, 42, true, done);
        CHECK(st.loaded() == 4);
        CHECK(done[7] == 1);
        std::vector<double> back(chunk_values(7).size());
        st.read(7, back.data());
        CHECK(back == chunk_values(7));
    }
    // a flipped byte inside the last record: its checksum fails, the records before it stay
    {
        fs::resize_file(path, full);  // chunks 3, 0, 28
        std::fstream io(path, std::ios::binary | std::ios::in | std::ios::out);
        io.seekp(static_cast<std::streamoff>(full - 20));
        io.put('\x7f');
    }
    {
        AtlasStore st(path, s, 42, true, done);
        CHECK(st.loaded() == 2);
        CHECK(done[28] == 0);
    }
    // another spec (fingerprint), or not a store: refused with --resume
    CHECK_THROWS_AS(AtlasStore(path, s, 43, true, done), std::invalid_argument);
    AtlasSpec other = s;
    other.chunk = 6;
    CHECK_THROWS_AS(AtlasStore(path, other, 42, true, done), std::invalid_argument);
    {
        std::ofstream out(dir / "junk");
        out << "not a store";
    }
    CHECK_THROWS_AS(AtlasStore(dir / "junk", s, 42, true, done), std::invalid_argument);
    // without resume: a fresh store; with resume and no store: a fresh store too
    {
        AtlasStore st(path, s, 42, false, done);
        CHECK(st.loaded() == 0);
    }
    {
        AtlasStore st(dir / "new.chunks", s, 42, true, done);
        CHECK(st.loaded() == 0);
    }
    CHECK(atlas_fingerprint("a") != atlas_fingerprint("b"));
}

TEST_CASE("atlas HDF5: the same values give the same bytes (no timestamps)") {
    const AtlasSpec s = parse_atlas_spec(good_spec, "a.toml").spec;
    std::vector<double> values(static_cast<std::size_t>(s.points()) * atlas_fields().size(), 0.5);
    const std::string a = atlas_hdf5(s, values, good_spec);
    const std::string b = atlas_hdf5(s, values, good_spec);
    CHECK(a == b);
    CHECK(a.compare(0, 8, std::string("\x89HDF\r\n\x1a\n", 8)) == 0);
    values[7] = 0.25;
    CHECK(atlas_hdf5(s, values, good_spec) != a);
    CHECK_THROWS_AS(atlas_hdf5(s, std::vector<double>(3), good_spec), std::invalid_argument);
}

TEST_CASE("atlas HDF5: a written file is recognised as the atlas of its spec, and only of it") {
    TempDir dir;
    const AtlasSpec s = parse_atlas_spec(good_spec, "a.toml").spec;
    std::vector<double> values(static_cast<std::size_t>(s.points()) * atlas_fields().size(), 1.0);
    const std::string path = dir / "atlas.h5";
    write_file_atomic(path, atlas_hdf5(s, values, good_spec));
    CHECK(atlas_hdf5_matches(path, good_spec));
    CHECK_FALSE(atlas_hdf5_matches(path, std::string(good_spec) + "# edited\n"));
    CHECK_FALSE(atlas_hdf5_matches(dir / "missing.h5", good_spec));
    CHECK_FALSE(atlas_hdf5_matches(dir.path.string(), good_spec));  // a folder
    write_file_atomic(path, "not HDF5");
    CHECK_FALSE(atlas_hdf5_matches(path, good_spec));
}

TEST_CASE("atlas HDF5: written in slabs from a chunk reader, the same bytes as in one piece") {
    TempDir dir;
    // chunks of 5 across the rows of the last axis (3 points): slabs and chunks never align
    const AtlasSpec s = parse_atlas_spec(good_spec, "a.toml").spec;
    const std::size_t nf = atlas_fields().size();
    std::vector<double> values(static_cast<std::size_t>(s.points()) * nf);
    for (std::size_t i = 0; i < values.size(); ++i) {
        const std::size_t q = i % nf;
        const AtlasField& f = atlas_fields()[q];
        values[i] = f.type == 'f' ? 0.001 * static_cast<double>(i) : f.type == 'i' ? static_cast<double>(i / nf % 1000) - 3.0 : static_cast<double>(i / nf % 2);
    }
    const std::string whole = atlas_hdf5(s, values, good_spec);
    long reads = 0;
    const AtlasChunkReader read = [&](long c, double* out) {
        ++reads;
        std::copy(values.begin() + s.chunk_begin(c) * static_cast<long>(nf), values.begin() + s.chunk_end(c) * static_cast<long>(nf), out);
    };
    // slabs of 1 point (the last axis split), 7 (a run of the last axis), 12 and 40 (runs of
    // planes), and the whole grid in one slab
    for (long slab : {1L, 7L, 12L, 40L, 1000L}) {
        CAPTURE(slab);
        const std::string path = dir / "a.h5";
        reads = 0;
        write_atlas_hdf5(path, s, read, good_spec, slab);
        std::ifstream in(path, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        CHECK(bytes == whole);
        CHECK(reads >= s.chunks());
        CHECK(reads <= 2 * s.chunks() + s.points() / slab + 1);  // a chunk is read again only where a slab cuts it
        CHECK(atlas_hdf5_matches(path, good_spec));
    }
    CHECK_THROWS_AS(write_atlas_hdf5(dir / "a.h5", s, read, good_spec, 0), std::invalid_argument);
    CHECK_THROWS_AS(write_atlas_hdf5(dir / "missing/a.h5", s, read, good_spec), WriteError);
}

TEST_CASE("atlas figure: from a chunk reader, and thinned to its point budget") {
    const AtlasFile f = parse_atlas_spec(good_spec, "a.toml");
    const std::size_t nf = atlas_fields().size();
    std::vector<double> values(static_cast<std::size_t>(f.spec.points()) * nf, 1.0);
    const std::string all = atlas_svg(f, values);
    CHECK(all.find("one point in") == std::string::npos);
    CHECK(all.find("panels)") == std::string::npos);
    const AtlasChunkReader read = [&](long c, double* out) {
        std::copy(values.begin() + f.spec.chunk_begin(c) * static_cast<long>(nf), values.begin() + f.spec.chunk_end(c) * static_cast<long>(nf), out);
    };
    CHECK(atlas_svg(f, read) == all);
    // 12 panels of 4 x 3 points; a budget of 48 points: every second point (2 x 2 per panel)
    const std::string thin = atlas_svg(f, read, 48);
    CHECK(thin.find("(one point in 2 along each axis)") != std::string::npos);
}
