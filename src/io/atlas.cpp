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
    refuse_unknown(source, root, {"title", "model", "rings", "chunk", "columns", "fixed", "axis"}, "");
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

AtlasStore::AtlasStore(const std::string& path, const AtlasSpec& spec, unsigned long long fingerprint, bool resume,
                       std::vector<double>& values, std::vector<char>& done)
    : m_path(path) {
    const std::size_t nf = atlas_fields().size();
    values.assign(static_cast<std::size_t>(spec.points()) * nf, 0.0);
    done.assign(static_cast<std::size_t>(spec.chunks()), 0);
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
                std::copy(buffer.begin(), buffer.end(), values.begin() + static_cast<std::ptrdiff_t>(spec.chunk_begin(h.chunk) * static_cast<long>(nf)));
                done[static_cast<std::size_t>(h.chunk)] = 1;
                ++m_loaded;
            }
            good += static_cast<off_t>(sizeof h + expect * sizeof(double) + sizeof sum);
        }
        const off_t end = ::lseek(m_fd, 0, SEEK_END);
        m_dropped = static_cast<long>(end - good);
        if (m_dropped > 0 && ::ftruncate(m_fd, good) != 0) fail("cannot cut the torn last record of", path, errno);
        if (::lseek(m_fd, good, SEEK_SET) < 0) fail("cannot seek in", path, errno);
        m_synced = std::chrono::steady_clock::now();
        return;
    }
    m_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (m_fd < 0) fail("cannot create the chunk store", path, errno);
    if (!write_all(m_fd, &want, sizeof want) || ::fsync(m_fd) != 0) fail("cannot write", path, errno);
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
    if (!write_all(m_fd, record.data(), record.size())) fail("cannot append a chunk to", m_path, errno ? errno : EIO);
    // written: the record survives the process (Ctrl-C, kill -9); synced at most once per
    // `sync_interval` so that the disk's latency (often 10 ms per fdatasync) never paces the work
    const auto now = std::chrono::steady_clock::now();
    if (now - m_synced >= std::chrono::duration<double>(m_sync_interval)) sync();
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

std::string atlas_hdf5(const AtlasSpec& spec, const std::vector<double>& values, const std::string& spec_text) {
    const auto& fields = atlas_fields();
    const std::size_t nf = fields.size();
    const std::size_t n = static_cast<std::size_t>(spec.points());
    if (values.size() != n * nf) throw std::invalid_argument("atlas_hdf5: expected points x fields values");
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by the return codes
    H5Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    check(H5Pset_fapl_core(fapl, 1 << 20, 0), "use the in-memory driver");
    H5Id fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
    check(H5Pset_obj_track_times(fcpl, 0), "switch timestamps off");
    H5Id file(H5Fcreate("atlas.h5", H5F_ACC_TRUNC, fcpl, fapl), H5Fclose);
    {
        H5Id root(H5Gopen2(file, "/", H5P_DEFAULT), H5Gclose);
        std::string dims = "ring";
        for (const auto& a : spec.axes) dims += "," + a.name;
        string_attribute(root, "spec", spec_text);
        string_attribute(root, "version", DDEMAP_VERSION);
        string_attribute(root, "model", spec.model);
        string_attribute(root, "dimensions", dims);
        long_attribute(root, "points", spec.points());
        long_attribute(root, "chunk_size", spec.chunk_size());
        std::vector<hsize_t> shape;
        for (long s : spec.shape()) shape.push_back(static_cast<hsize_t>(s));
        std::vector<double> f64(n);
        std::vector<int> i32(n);
        std::vector<unsigned char> u8(n);
        for (std::size_t k = 0; k < nf; ++k) {
            const AtlasField& f = fields[k];
            if (f.type == 'f') {
                for (std::size_t i = 0; i < n; ++i) f64[i] = values[i * nf + k];
                dataset(root, f.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, shape, f64.data(), f.description, dims);
            } else if (f.type == 'i') {
                for (std::size_t i = 0; i < n; ++i) i32[i] = static_cast<int>(values[i * nf + k]);
                dataset(root, f.name, H5T_STD_I32LE, H5T_NATIVE_INT, shape, i32.data(), f.description, dims);
            } else {
                for (std::size_t i = 0; i < n; ++i) u8[i] = values[i * nf + k] != 0.0 ? 1 : 0;
                dataset(root, f.name, H5T_STD_U8LE, H5T_NATIVE_UCHAR, shape, u8.data(), f.description, dims);
            }
        }
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

std::string atlas_svg(const AtlasFile& file, const std::vector<double>& values) {
    const AtlasSpec& spec = file.spec;
    const std::size_t nf = atlas_fields().size();
    const std::size_t na = spec.axes.size();
    const Axis ax = spec.axes[na - 2].sweep_axis();
    const Axis ay = spec.axes[na - 1].sweep_axis();
    const long plane = static_cast<long>(ax.count) * ay.count;
    const long panels = spec.points() / plane;
    std::vector<SweepResult> sweeps(static_cast<std::size_t>(panels));
    std::vector<ChartPanel> chart(static_cast<std::size_t>(panels));
    auto unit_of = [&](const std::string& name) {
        for (const auto& ps : model_parameters(spec.model))
            if (ps.name == name && ps.unit != "1") return " " + unit_text(ps.unit);
        return std::string();
    };
    for (long q = 0; q < panels; ++q) {
        SweepResult& sw = sweeps[static_cast<std::size_t>(q)];
        const long first = q * plane;
        sw.spec.model = spec.model;
        sw.spec.x = ax;
        sw.spec.y = ay;
        sw.spec.cars = spec.ring_at(first);
        sw.points.resize(static_cast<std::size_t>(plane));
        for (int ix = 0; ix < ax.count; ++ix) {
            for (int iy = 0; iy < ay.count; ++iy) {  // atlas: y innermost; sweep: x innermost
                SweepPoint p = atlas_point(&values[static_cast<std::size_t>(first + static_cast<long>(ix) * ay.count + iy) * nf]);
                p.x = ax.value(ix);
                p.y = ay.value(iy);
                sw.points[static_cast<std::size_t>(iy) * ax.count + ix] = p;
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
    int columns = file.columns;
    if (columns == 0) columns = na > 2 ? static_cast<int>(std::min<std::size_t>(6, spec.axes[na - 3].values.size())) : static_cast<int>(std::min<std::size_t>(6, spec.rings.size()));
    co.columns = std::max(1, columns);
    co.panel_width = 220;
    co.panel_height = 190;
    return render_chart_svg(chart, co);
}

}  // namespace ddemap
