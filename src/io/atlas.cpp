#include "ddemap/io/atlas.hpp"

#include "core/internal/text.hpp"
#include "io/internal/toml_fields.hpp"

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstring>
#include <iomanip>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>
#include <toml++/toml.h>

#include "ddemap/io/files.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap {

// ---------------------------------------------------------------------------------------------
// spec

namespace {

using detail::toml_integer_in;
using detail::toml_number;
using detail::toml_where;

std::string short_number(double v) {  // 4 significant digits: a title, not data
    std::ostringstream os;
    os << std::setprecision(4) << v;
    return os.str();
}

void refuse_unknown(const std::string& source, const toml::table& t, std::initializer_list<const char*> known, const std::string& prefix) {
    for (const auto& [k, v] : t) {
        const std::string key(k.str());
        if (std::find_if(known.begin(), known.end(), [&](const char* s) { return key == s; }) == known.end()) {
            throw std::invalid_argument(toml_where(source, v) + ": unknown key " + detail::quoted(prefix + key));
        }
    }
}

int ring_value(const std::string& source, const toml::node& n) {
    if (auto s = n.value<std::string>(); s && *s == "inf") return 0;
    if (auto v = toml_integer_in(n, 2, 1000000000)) return static_cast<int>(*v);
    throw std::invalid_argument(toml_where(source, n) + ": rings: expected integers N from 2 to 1e9 or \"inf\"");
}

AtlasAxis read_axis(const std::string& source, const toml::node& n, std::size_t index) {
    const std::string key = "axis[" + std::to_string(index + 1) + "]";
    const toml::table* t = n.as_table();
    if (!t) throw std::invalid_argument(toml_where(source, n) + ": " + key + ": expected an [[axis]] table");
    refuse_unknown(source, *t, {"name", "values", "lo", "hi", "count"}, key + ".");
    AtlasAxis a;
    const toml::node* name = t->get("name");
    if (!name || !name->is_string()) throw std::invalid_argument(toml_where(source, n) + ": " + key + ".name: expected a parameter name");
    a.name = *name->value<std::string>();
    const toml::node* values = t->get("values");
    const bool range = t->get("lo") || t->get("hi") || t->get("count");
    if (values && range) throw std::invalid_argument(toml_where(source, n) + ": " + key + ": expected either values or lo, hi, count, not both");
    if (values) {
        const toml::array* arr = values->as_array();
        if (!arr || arr->empty() || arr->size() > 100000)
            throw std::invalid_argument(toml_where(source, *values) + ": " + key + ".values: expected an array of 1 to 100000 numbers");
        for (const auto& v : *arr) a.values.push_back(toml_number(source, v, key + ".values"));
        return a;
    }
    for (const char* k : {"lo", "hi", "count"})
        if (!t->get(k)) throw std::invalid_argument(toml_where(source, n) + ": " + key + "." + k + " missing (or give values = [...])");
    Axis ax;
    ax.name = a.name;
    ax.lo = toml_number(source, *t->get("lo"), key + ".lo");
    ax.hi = toml_number(source, *t->get("hi"), key + ".hi");
    const auto c = toml_integer_in(*t->get("count"), 2, 100000);
    if (!c || !(ax.lo < ax.hi)) {
        throw std::invalid_argument(toml_where(source, n) + ": " + key + ": expected lo < hi and an integer count from 2 to 100000");
    }
    ax.count = static_cast<int>(*c);
    for (int i = 0; i < ax.count; ++i) a.values.push_back(ax.value(i));
    a.uniform = true;
    a.lo = ax.lo;
    a.hi = ax.hi;
    return a;
}

}  // namespace

AtlasFile parse_atlas_spec(const std::string& text, const std::string& source) {
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        std::ostringstream os;
        os << source << ":" << e.source().begin.line << ": " << detail::escaped(std::string(e.description()));
        throw std::invalid_argument(os.str());
    }
    refuse_unknown(source, root, {"title", "model", "rings", "chunk", "columns", "ring_method", "fixed", "axis"}, "");
    AtlasFile file;
    AtlasSpec& spec = file.spec;
    if (const toml::node* t = root.get("title")) {
        if (!t->is_string()) throw std::invalid_argument(toml_where(source, *t) + ": title: expected a string");
        spec.title = *t->value<std::string>();
    }
    if (const toml::node* m = root.get("model")) {
        if (!m->is_string()) throw std::invalid_argument(toml_where(source, *m) + ": model: expected a model name");
        spec.model = *m->value<std::string>();
    }
    if (const toml::node* r = root.get("rings")) {
        const toml::array* arr = r->as_array();
        if (!arr || arr->empty() || arr->size() > 64)
            throw std::invalid_argument(toml_where(source, *r) + ": rings: expected an array of 1 to 64 ring sizes (N or \"inf\")");
        spec.rings.clear();
        for (const auto& v : *arr) spec.rings.push_back(ring_value(source, v));
    }
    if (const toml::node* c = root.get("chunk")) {
        const auto v = toml_integer_in(*c, 1, 1000000);
        if (!v) throw std::invalid_argument(toml_where(source, *c) + ": chunk: expected an integer from 1 to 1000000 (points per chunk)");
        spec.chunk = static_cast<long>(*v);
    }
    if (const toml::node* m = root.get("ring_method")) {
        const auto v = m->value<std::string>();
        if (!m->is_string() || (*v != "auto" && *v != "winding" && *v != "modes"))
            throw std::invalid_argument(toml_where(source, *m) + ": ring_method: expected \"auto\", \"winding\" or \"modes\"");
        spec.ring_method = *v;
    }
    if (const toml::node* c = root.get("columns")) {
        const auto v = toml_integer_in(*c, 1, 64);
        if (!v) throw std::invalid_argument(toml_where(source, *c) + ": columns: expected an integer from 1 to 64");
        file.columns = static_cast<int>(*v);
    }
    if (const toml::node* f = root.get("fixed")) {
        if (!f->is_table()) throw std::invalid_argument(toml_where(source, *f) + ": fixed: expected a table of parameters");
        for (const auto& [k, v] : *f->as_table()) spec.fixed[std::string(k.str())] = toml_number(source, v, "fixed." + std::string(k.str()));
    }
    const toml::node* axes = root.get("axis");
    if (!axes) throw std::invalid_argument(source + ": [[axis]] tables missing: expected 2 to 5 swept parameters");
    const toml::array* arr = axes->as_array();
    if (!arr) throw std::invalid_argument(toml_where(source, *axes) + ": axis: expected [[axis]] tables");
    for (std::size_t i = 0; i < arr->size(); ++i) spec.axes.push_back(read_axis(source, *arr->get(i), i));
    try {
        spec.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(source + ": " + e.what());
    }
    return file;
}

unsigned long long atlas_fingerprint(const std::string& spec_text) {
    const std::string version = std::string("ddemap ") + DDEMAP_VERSION + "\n";
    return fnv1a64(spec_text.data(), spec_text.size(), fnv1a64(version.data(), version.size()));
}

// ---------------------------------------------------------------------------------------------
// chunk store

namespace {

constexpr char store_magic[16] = {'d', 'd', 'e', 'm', 'a', 'p', '-', 'a', 't', 'l', 'a', 's', '-', 'v', '1', '\n'};
constexpr unsigned long long record_magic = 0x4b4e554843534c41ull;  // "ALSCHUNK"

struct StoreHeader {
    char magic[16];
    unsigned long long fingerprint;
    long long points;
    long long chunk_size;
    long long fields;
};

struct RecordHead {
    unsigned long long magic;
    long long chunk;
    unsigned long long count;
};

[[noreturn]] void fail(const std::string& what, const std::string& path, int err) {
    throw WriteError(what + " " + path + ": " + std::strerror(err));
}

bool write_all(int fd, const void* data, std::size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= static_cast<std::size_t>(n);
    }
    return true;
}

bool read_all(int fd, void* data, std::size_t size) {
    char* p = static_cast<char*>(data);
    while (size > 0) {
        const ssize_t n = ::read(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= static_cast<std::size_t>(n);
    }
    return true;
}

unsigned long long record_checksum(const RecordHead& h, const double* values) {
    const unsigned long long s = fnv1a64(&h, sizeof h);
    return fnv1a64(values, h.count * sizeof(double), s);
}

}  // namespace

AtlasStore::AtlasStore(const std::string& path, const AtlasSpec& spec, unsigned long long fingerprint, bool resume, std::vector<char>& done)
    : m_path(path), m_spec(spec) {
    const std::size_t nf = atlas_fields().size();
    done.assign(static_cast<std::size_t>(spec.chunks()), 0);
    m_offset.assign(static_cast<std::size_t>(spec.chunks()), -1);
    StoreHeader want{};
    std::memcpy(want.magic, store_magic, sizeof store_magic);
    want.fingerprint = fingerprint;
    want.points = spec.points();
    want.chunk_size = spec.chunk_size();
    want.fields = static_cast<long long>(nf);

    struct stat st {};
    const bool exists = ::stat(path.c_str(), &st) == 0;
    if (resume && exists) {
        m_fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
        if (m_fd < 0) fail("cannot open the chunk store", path, errno);
        StoreHeader have{};
        if (!read_all(m_fd, &have, sizeof have) || std::memcmp(have.magic, store_magic, sizeof store_magic) != 0) {
            ::close(m_fd);
            m_fd = -1;
            throw std::invalid_argument("--resume: '" + path + "' is not an atlas chunk store (remove it, or run without --resume)");
        }
        if (have.fingerprint != want.fingerprint || have.points != want.points || have.chunk_size != want.chunk_size || have.fields != want.fields) {
            ::close(m_fd);
            m_fd = -1;
            throw std::invalid_argument("--resume: '" + path + "' was written for another spec or ddemap version (the spec's text must be unchanged); run without --resume to start afresh");
        }
        // every complete record is checked (length and checksum) and indexed; its values stay
        // in the file (read back by read())
        off_t good = static_cast<off_t>(sizeof have);
        std::vector<double> buffer;
        for (;;) {
            RecordHead h{};
            if (!read_all(m_fd, &h, sizeof h)) break;
            if (h.magic != record_magic || h.chunk < 0 || h.chunk >= spec.chunks()) break;
            const std::size_t expect = static_cast<std::size_t>(spec.chunk_end(h.chunk) - spec.chunk_begin(h.chunk)) * nf;
            if (h.count != expect) break;
            buffer.resize(expect);
            unsigned long long sum = 0;
            if (!read_all(m_fd, buffer.data(), expect * sizeof(double)) || !read_all(m_fd, &sum, sizeof sum)) break;
            if (sum != record_checksum(h, buffer.data())) break;
            if (!done[static_cast<std::size_t>(h.chunk)]) {
                done[static_cast<std::size_t>(h.chunk)] = 1;
                m_offset[static_cast<std::size_t>(h.chunk)] = static_cast<long long>(good) + static_cast<long long>(sizeof h);
                ++m_loaded;
            }
            good += static_cast<off_t>(sizeof h + expect * sizeof(double) + sizeof sum);
        }
        const off_t end = ::lseek(m_fd, 0, SEEK_END);
        m_dropped = static_cast<long>(end - good);
        if (m_dropped > 0 && ::ftruncate(m_fd, good) != 0) fail("cannot cut the torn last record of", path, errno);
        if (::lseek(m_fd, good, SEEK_SET) < 0) fail("cannot seek in", path, errno);
        m_end = static_cast<long long>(good);
        m_synced = std::chrono::steady_clock::now();
        return;
    }
    m_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (m_fd < 0) fail("cannot create the chunk store", path, errno);
    if (!write_all(m_fd, &want, sizeof want) || ::fsync(m_fd) != 0) fail("cannot write", path, errno);
    m_end = static_cast<long long>(sizeof want);
    m_synced = std::chrono::steady_clock::now();
}

AtlasStore::~AtlasStore() {
    if (m_fd >= 0) {
        ::fdatasync(m_fd);
        ::close(m_fd);
    }
}

void AtlasStore::append(long c, const double* values, std::size_t count) {
    RecordHead h{record_magic, c, count};
    const unsigned long long sum = record_checksum(h, values);
    std::string record(sizeof h + count * sizeof(double) + sizeof sum, '\0');
    std::memcpy(&record[0], &h, sizeof h);
    std::memcpy(&record[sizeof h], values, count * sizeof(double));
    std::memcpy(&record[sizeof h + count * sizeof(double)], &sum, sizeof sum);
    if (c < 0 || c >= m_spec.chunks() || m_offset[static_cast<std::size_t>(c)] >= 0)
        throw std::invalid_argument("atlas store: chunk " + std::to_string(c) + " is outside the atlas or stored twice");
    if (!write_all(m_fd, record.data(), record.size())) fail("cannot append a chunk to", m_path, errno ? errno : EIO);
    m_offset[static_cast<std::size_t>(c)] = m_end + static_cast<long long>(sizeof h);
    m_end += static_cast<long long>(record.size());
    // written: the record survives the process (Ctrl-C, kill -9); synced at most once per
    // `sync_interval` so that the disk's latency (often 10 ms per fdatasync) never paces the work
    const auto now = std::chrono::steady_clock::now();
    if (now - m_synced >= std::chrono::duration<double>(m_sync_interval)) sync();
}

void AtlasStore::read(long c, double* out) const {
    if (c < 0 || c >= m_spec.chunks() || m_offset[static_cast<std::size_t>(c)] < 0)
        throw std::invalid_argument("atlas store: chunk " + std::to_string(c) + " is not in " + m_path);
    const std::size_t bytes = static_cast<std::size_t>(m_spec.chunk_end(c) - m_spec.chunk_begin(c)) * atlas_fields().size() * sizeof(double);
    char* p = reinterpret_cast<char*>(out);
    off_t at = static_cast<off_t>(m_offset[static_cast<std::size_t>(c)]);
    for (std::size_t left = bytes; left > 0;) {
        const ssize_t n = ::pread(m_fd, p, left, at);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw std::runtime_error("cannot read chunk " + std::to_string(c) + " back from " + m_path + ": " + (n < 0 ? std::strerror(errno) : "the file is shorter"));
        p += n;
        at += n;
        left -= static_cast<std::size_t>(n);
    }
}

AtlasChunkReader AtlasStore::reader() const {
    return [this](long c, double* out) { read(c, out); };
}

void AtlasStore::sync() {
    if (::fdatasync(m_fd) != 0) fail("cannot sync", m_path, errno);
    m_synced = std::chrono::steady_clock::now();
}

// ---------------------------------------------------------------------------------------------
// HDF5

namespace {

/// Closes an HDF5 identifier at scope exit.
struct H5Id {
    hid_t id;
    herr_t (*close)(hid_t);
    H5Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {
        if (id < 0) throw std::runtime_error("HDF5: cannot create an object of the atlas file");
    }
    ~H5Id() { close(id); }
    H5Id(const H5Id&) = delete;
    H5Id& operator=(const H5Id&) = delete;
    operator hid_t() const { return id; }
};

void check(herr_t e, const char* what) {
    if (e < 0) throw std::runtime_error(std::string("HDF5: cannot ") + what);
}

void string_attribute(hid_t obj, const char* name, const std::string& value) {
    H5Id type(H5Tcopy(H5T_C_S1), H5Tclose);
    check(H5Tset_size(type, std::max<std::size_t>(1, value.size())), "size a string");
    check(H5Tset_strpad(type, H5T_STR_NULLPAD), "pad a string");
    check(H5Tset_cset(type, H5T_CSET_UTF8), "set UTF-8");
    H5Id space(H5Screate(H5S_SCALAR), H5Sclose);
    H5Id attr(H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    std::string padded = value;
    if (padded.empty()) padded.push_back('\0');
    check(H5Awrite(attr, type, padded.data()), "write an attribute");
}

void long_attribute(hid_t obj, const char* name, long long value) {
    H5Id space(H5Screate(H5S_SCALAR), H5Sclose);
    H5Id attr(H5Acreate2(obj, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    check(H5Awrite(attr, H5T_NATIVE_LLONG, &value), "write an attribute");
}

/// A dataset without timestamps (the same values give the same bytes).
void dataset(hid_t where, const std::string& name, hid_t file_type, hid_t mem_type, const std::vector<hsize_t>& dims, const void* data,
             const std::string& description, const std::string& dimensions) {
    H5Id space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
    H5Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    check(H5Pset_obj_track_times(dcpl, 0), "switch timestamps off");
    H5Id ds(H5Dcreate2(where, name.c_str(), file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose);
    check(H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write a dataset");
    string_attribute(ds, "description", description);
    if (!dimensions.empty()) string_attribute(ds, "dimensions", dimensions);
}

}  // namespace

namespace {

/// A dataset of the grid's shape, created empty (contiguous, allocated at creation, no fill:
/// every value is written by the slabs), with its attributes.
hid_t grid_dataset(hid_t where, const AtlasField& f, hid_t file_type, const std::vector<hsize_t>& dims, const std::string& dimensions) {
    H5Id space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
    H5Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    check(H5Pset_obj_track_times(dcpl, 0), "switch timestamps off");
    check(H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY), "allocate a dataset");
    check(H5Pset_fill_time(dcpl, H5D_FILL_TIME_NEVER), "switch the fill off");
    const hid_t ds = H5Dcreate2(where, f.name, file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds < 0) throw std::runtime_error(std::string("HDF5: cannot create the dataset ") + f.name);
    try {
        string_attribute(ds, "description", f.description);
        string_attribute(ds, "dimensions", dimensions);
    } catch (...) {
        H5Dclose(ds);
        throw;
    }
    return ds;
}

/// The atlas into an open, empty file: attributes, coordinates, then the datasets slab by slab.
void fill_atlas_file(hid_t file, const AtlasSpec& spec, const AtlasChunkReader& read, const std::string& spec_text, long slab_points) {
    const auto& fields = atlas_fields();
    const std::size_t nf = fields.size();
    H5Id root(H5Gopen2(file, "/", H5P_DEFAULT), H5Gclose);
    std::string dims_text = "ring";
    for (const auto& a : spec.axes) dims_text += "," + a.name;
    string_attribute(root, "spec", spec_text);
    string_attribute(root, "version", DDEMAP_VERSION);
    string_attribute(root, "model", spec.model);
    string_attribute(root, "dimensions", dims_text);
    long_attribute(root, "points", spec.points());
    long_attribute(root, "chunk_size", spec.chunk_size());
    string_attribute(root, "ring_method", spec.ring_method_used());
    std::vector<hsize_t> dims;
    for (long s : spec.shape()) dims.push_back(static_cast<hsize_t>(s));
    {
        H5Id gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
        check(H5Pset_obj_track_times(gcpl, 0), "switch timestamps off");
        H5Id coords(H5Gcreate2(file, "coordinates", H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose);
        std::vector<int> rings(spec.rings.begin(), spec.rings.end());
        dataset(coords, "ring", H5T_STD_I32LE, H5T_NATIVE_INT, {rings.size()}, rings.data(), "ring size N (0: infinity)", "");
        for (const auto& a : spec.axes) {
            std::string unit;
            for (const auto& ps : model_parameters(spec.model))
                if (ps.name == a.name) unit = ps.unit;
            dataset(coords, a.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {a.values.size()}, a.values.data(),
                    a.name + (unit.empty() ? std::string() : " [" + unit + "]"), "");
        }
    }
    std::vector<hid_t> sets;
    struct CloseAll {
        std::vector<hid_t>& ids;
        ~CloseAll() {
            for (hid_t id : ids) H5Dclose(id);
        }
    } close_all{sets};
    for (const AtlasField& f : fields)
        sets.push_back(grid_dataset(root, f, f.type == 'f' ? H5T_IEEE_F64LE : f.type == 'i' ? H5T_STD_I32LE : H5T_STD_U8LE, dims, dims_text));

    // Slabs: flat (C order) ranges that are hyperslabs: dimension k is the outermost whose
    // trailing block (the product of the dimensions after it) holds at most slab_points points;
    // a slab fixes the indices before k and takes a run of dimension k with everything after it.
    const int rank = static_cast<int>(dims.size());
    int k = rank - 1;
    hsize_t inner = 1;  // points per index of dimension k
    while (k > 0 && inner * dims[static_cast<std::size_t>(k)] <= static_cast<hsize_t>(slab_points)) {
        inner *= dims[static_cast<std::size_t>(k)];
        --k;
    }
    const hsize_t run = std::max<hsize_t>(1, static_cast<hsize_t>(slab_points) / inner);  // indices of dimension k per slab
    const long total = spec.points();
    const long cs = spec.chunk_size();
    std::vector<double> chunk(static_cast<std::size_t>(cs) * nf), f64;
    std::vector<int> i32;
    std::vector<unsigned char> u8;
    std::vector<double> slab;
    long loaded = -1;  // the chunk in `chunk`
    for (long a = 0; a < total;) {
        // the slab's start as indices, and its run in dimension k
        std::vector<hsize_t> start(static_cast<std::size_t>(rank), 0), count(dims);
        long rest = a;
        for (int d = rank - 1; d >= 0; --d) {
            start[static_cast<std::size_t>(d)] = static_cast<hsize_t>(rest) % dims[static_cast<std::size_t>(d)];
            rest /= static_cast<long>(dims[static_cast<std::size_t>(d)]);
        }
        for (int d = 0; d < k; ++d) count[static_cast<std::size_t>(d)] = 1;
        count[static_cast<std::size_t>(k)] = std::min(run, dims[static_cast<std::size_t>(k)] - start[static_cast<std::size_t>(k)]);
        const long b = a + static_cast<long>(count[static_cast<std::size_t>(k)] * inner);
        const std::size_t n = static_cast<std::size_t>(b - a);
        slab.resize(n * nf);
        for (long c = a / cs; c * cs < b; ++c) {
            if (c != loaded) {
                read(c, chunk.data());
                loaded = c;
            }
            const long lo = std::max(a, c * cs), hi = std::min(b, spec.chunk_end(c));
            std::copy(chunk.begin() + (lo - c * cs) * static_cast<long>(nf), chunk.begin() + (hi - c * cs) * static_cast<long>(nf),
                      slab.begin() + (lo - a) * static_cast<long>(nf));
        }
        H5Id file_space(H5Screate_simple(rank, dims.data(), nullptr), H5Sclose);
        check(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), "select a slab");
        const hsize_t flat = n;
        H5Id mem_space(H5Screate_simple(1, &flat, nullptr), H5Sclose);
        for (std::size_t q = 0; q < nf; ++q) {
            const AtlasField& f = fields[q];
            if (f.type == 'f') {
                f64.resize(n);
                for (std::size_t i = 0; i < n; ++i) f64[i] = slab[i * nf + q];
                check(H5Dwrite(sets[q], H5T_NATIVE_DOUBLE, mem_space, file_space, H5P_DEFAULT, f64.data()), "write a slab");
            } else if (f.type == 'i') {
                i32.resize(n);
                for (std::size_t i = 0; i < n; ++i) i32[i] = static_cast<int>(slab[i * nf + q]);
                check(H5Dwrite(sets[q], H5T_NATIVE_INT, mem_space, file_space, H5P_DEFAULT, i32.data()), "write a slab");
            } else {
                u8.resize(n);
                for (std::size_t i = 0; i < n; ++i) u8[i] = slab[i * nf + q] != 0.0 ? 1 : 0;
                check(H5Dwrite(sets[q], H5T_NATIVE_UCHAR, mem_space, file_space, H5P_DEFAULT, u8.data()), "write a slab");
            }
        }
        a = b;
    }
}

/// A file creation property list without timestamps.
hid_t plain_fcpl() {
    const hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    if (fcpl >= 0 && H5Pset_obj_track_times(fcpl, 0) < 0) {
        H5Pclose(fcpl);
        return -1;
    }
    return fcpl;
}

}  // namespace

void write_atlas_hdf5(const std::string& path, const AtlasSpec& spec, const AtlasChunkReader& read, const std::string& spec_text,
                      long slab_points) {
    if (slab_points < 1) throw std::invalid_argument("write_atlas_hdf5: expected slab_points >= 1");
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by the return codes
    const std::string part = path + ".part";
    H5Id fcpl(plain_fcpl(), H5Pclose);
    const hid_t f = H5Fcreate(part.c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT);
    if (f < 0) throw WriteError("cannot create the HDF5 file " + part);
    try {
        H5Id file(f, H5Fclose);
        fill_atlas_file(file, spec, read, spec_text, slab_points);
        if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw WriteError("cannot write the HDF5 file " + part);
    } catch (...) {
        ::unlink(part.c_str());
        throw;
    }
    // on disk before it is moved into place, then the folder
    const int fd = ::open(part.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
        const int err = errno;
        if (fd >= 0) ::close(fd);
        fail("cannot sync", part, err);
    }
    ::close(fd);
    if (::rename(part.c_str(), path.c_str()) != 0) fail("cannot move " + part + " to", path, errno);
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0) fail("cannot open the folder of", path, errno);
    const int rc = ::fsync(dfd);
    const int err = errno;
    ::close(dfd);
    if (rc != 0 && err != EINVAL) fail("cannot sync the folder of", path, err);
}

std::string atlas_hdf5(const AtlasSpec& spec, const std::vector<double>& values, const std::string& spec_text) {
    const std::size_t nf = atlas_fields().size();
    const std::size_t n = static_cast<std::size_t>(spec.points());
    if (values.size() != n * nf) throw std::invalid_argument("atlas_hdf5: expected points x fields values");
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by the return codes
    H5Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    check(H5Pset_fapl_core(fapl, 1 << 20, 0), "use the in-memory driver");
    H5Id fcpl(plain_fcpl(), H5Pclose);
    H5Id file(H5Fcreate("atlas.h5", H5F_ACC_TRUNC, fcpl, fapl), H5Fclose);
    const auto read = [&](long c, double* out) {
        std::copy(values.begin() + spec.chunk_begin(c) * static_cast<long>(nf), values.begin() + spec.chunk_end(c) * static_cast<long>(nf), out);
    };
    fill_atlas_file(file, spec, read, spec_text, 1L << 16);
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush the file");
    const ssize_t size = H5Fget_file_image(file, nullptr, 0);
    if (size <= 0) throw std::runtime_error("HDF5: cannot take the file image");
    std::string image(static_cast<std::size_t>(size), '\0');
    if (H5Fget_file_image(file, &image[0], image.size()) != size) throw std::runtime_error("HDF5: cannot take the file image");
    return image;
}

namespace {

/// A string attribute of the root group, or nullopt.
std::optional<std::string> read_string_attribute(hid_t file, const char* name) {
    if (H5Aexists_by_name(file, "/", name, H5P_DEFAULT) <= 0) return std::nullopt;
    const hid_t attr = H5Aopen_by_name(file, "/", name, H5P_DEFAULT, H5P_DEFAULT);
    if (attr < 0) return std::nullopt;
    H5Id a(attr, H5Aclose);
    H5Id type(H5Aget_type(a), H5Tclose);
    if (H5Tget_class(type) != H5T_STRING || H5Tis_variable_str(type) != 0) return std::nullopt;
    const std::size_t size = H5Tget_size(type);
    std::string value(size, '\0');
    if (H5Aread(a, type, &value[0]) < 0) return std::nullopt;
    while (!value.empty() && value.back() == '\0') value.pop_back();
    return value;
}

}  // namespace

bool atlas_hdf5_matches(const std::string& path, const std::string& spec_text) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) return false;
    try {
        H5Id file(f, H5Fclose);
        return read_string_attribute(file, "spec") == spec_text && read_string_attribute(file, "version") == std::string(DDEMAP_VERSION);
    } catch (const std::exception&) {
        return false;
    }
}

// ---------------------------------------------------------------------------------------------
// figure

std::string atlas_svg(const AtlasFile& file, const AtlasChunkReader& read, long budget) {
    const AtlasSpec& spec = file.spec;
    const std::size_t nf = atlas_fields().size();
    const std::size_t na = spec.axes.size();
    const Axis ax = spec.axes[na - 2].sweep_axis();
    const Axis ay = spec.axes[na - 1].sweep_axis();
    const long plane = static_cast<long>(ax.count) * ay.count;
    const long all_panels = spec.points() / plane;
    // the figure's size: at most kAtlasFigurePanels panels, every `stride`-th point of each
    // axis of the plane so that the panels hold at most `budget` points
    const long panels = std::min(all_panels, kAtlasFigurePanels);
    budget = std::max(budget, 4 * panels);
    int stride = 1;
    auto cells = [&](int s) { return static_cast<long>((ax.count - 1) / s + 1) * static_cast<long>((ay.count - 1) / s + 1) * panels; };
    while (cells(stride) > budget && stride < std::max(ax.count, ay.count)) ++stride;
    Axis sx = ax, sy = ay;  // the sampled axes: indices 0, stride, 2 stride, ...
    sx.count = (ax.count - 1) / stride + 1;
    sy.count = (ay.count - 1) / stride + 1;
    sx.hi = ax.value((sx.count - 1) * stride);
    sy.hi = ay.value((sy.count - 1) * stride);
    if (sx.count < 2) sx.hi = ax.hi, sx.count = 2;  // (not reached: budget >= 4 points per panel)
    if (sy.count < 2) sy.hi = ay.hi, sy.count = 2;
    std::vector<SweepResult> sweeps(static_cast<std::size_t>(panels));
    std::vector<ChartPanel> chart(static_cast<std::size_t>(panels));
    auto unit_of = [&](const std::string& name) {
        for (const auto& ps : model_parameters(spec.model))
            if (ps.name == name && ps.unit != "1") return " " + unit_text(ps.unit);
        return std::string();
    };
    std::vector<double> chunk(static_cast<std::size_t>(spec.chunk_size()) * nf);
    long loaded = -1;
    auto point = [&](long i) {  // the values of point i (its chunk read once while the points come in order)
        const long c = i / spec.chunk_size();
        if (c != loaded) {
            read(c, chunk.data());
            loaded = c;
        }
        return &chunk[static_cast<std::size_t>(i - spec.chunk_begin(c)) * nf];
    };
    for (long q = 0; q < panels; ++q) {
        SweepResult& sw = sweeps[static_cast<std::size_t>(q)];
        const long first = q * plane;
        sw.spec.model = spec.model;
        sw.spec.x = sx;
        sw.spec.y = sy;
        sw.spec.cars = spec.ring_at(first);
        sw.points.resize(static_cast<std::size_t>(sx.count) * static_cast<std::size_t>(sy.count));
        for (int ix = 0; ix < sx.count; ++ix) {
            for (int iy = 0; iy < sy.count; ++iy) {  // atlas: y innermost; sweep: x innermost
                SweepPoint p = atlas_point(point(first + static_cast<long>(ix) * stride * ay.count + static_cast<long>(iy) * stride));
                p.x = ax.value(ix * stride);
                p.y = ay.value(iy * stride);
                sw.points[static_cast<std::size_t>(iy) * static_cast<std::size_t>(sx.count) + static_cast<std::size_t>(ix)] = p;
            }
        }
        const ParameterMap pm = spec.parameters_at(first);
        std::string title = "N = " + (sw.spec.cars == 0 ? std::string("∞") : std::to_string(sw.spec.cars));
        for (std::size_t k = 0; k + 2 < na; ++k) {
            const std::string& name = spec.axes[k].name;
            title += ", " + parameter_symbol(name) + " = " + short_number(pm.at(name)) + unit_of(name);
        }
        chart[static_cast<std::size_t>(q)].title = title;
        chart[static_cast<std::size_t>(q)].sweep = &sw;
    }
    ChartOptions co;
    if (spec.title.empty()) {
        co.title = "Atlas: " + spec.model;
        for (const auto& [k, v] : spec.fixed) co.title += ", " + parameter_symbol(k) + " = " + short_number(v) + unit_of(k);
    } else {
        co.title = spec.title;
    }
    if (panels < all_panels) co.title += " (the first " + std::to_string(panels) + " of " + std::to_string(all_panels) + " panels)";
    if (stride > 1) co.title += " (one point in " + std::to_string(stride) + " along each axis)";
    int columns = file.columns;
    if (columns == 0) columns = na > 2 ? static_cast<int>(std::min<std::size_t>(6, spec.axes[na - 3].values.size())) : static_cast<int>(std::min<std::size_t>(6, spec.rings.size()));
    co.columns = std::max(1, columns);
    co.panel_width = 220;
    co.panel_height = 190;
    return render_chart_svg(chart, co);
}

std::string atlas_svg(const AtlasFile& file, const std::vector<double>& values) {
    const AtlasSpec& spec = file.spec;
    const long nf = static_cast<long>(atlas_fields().size());
    if (values.size() != static_cast<std::size_t>(spec.points() * nf)) throw std::invalid_argument("atlas_svg: expected points x fields values");
    return atlas_svg(file, [&](long c, double* out) { std::copy(values.begin() + spec.chunk_begin(c) * nf, values.begin() + spec.chunk_end(c) * nf, out); });
}

}  // namespace ddemap
