#include "ddemap/io/files.hpp"

#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

std::string reason(int err) { return std::strerror(err); }

std::string dir_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    if (slash == 0) return "/";
    return path.substr(0, slash);
}

std::string base_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

// ---- hidden temporary files named on disk, removed by an interrupt -------------------------
// Only async-signal-safe calls in the handler: unlink, sigaction, raise.

constexpr int max_named = 64;
char g_named[max_named][PATH_MAX];
volatile std::sig_atomic_t g_named_used[max_named];
const int g_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

extern "C" void remove_named_and_reraise(int sig) {
    for (int i = 0; i < max_named; ++i)
        if (g_named_used[i]) ::unlink(g_named[i]);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    ::sigaction(sig, &dfl, nullptr);
    ::raise(sig);
}

/// Registers an absolute or relative path for removal on an interrupt; -1 when the table is full.
int register_named(const std::string& path) {
    if (path.size() >= PATH_MAX) return -1;
    for (int i = 0; i < max_named; ++i) {
        if (g_named_used[i]) continue;
        std::memcpy(g_named[i], path.c_str(), path.size() + 1);
        g_named_used[i] = 1;
        return i;
    }
    return -1;
}

void unregister_named(int slot) {
    if (slot >= 0) g_named_used[slot] = 0;
}

/// Installs the interrupt handler for the lifetime of the object (the previous ones after).
struct InterruptCleanup {
    struct sigaction old[4];
    InterruptCleanup() {
        struct sigaction sa {};
        sa.sa_handler = remove_named_and_reraise;
        sigemptyset(&sa.sa_mask);
        for (int i = 0; i < 4; ++i) ::sigaction(g_signals[i], &sa, &old[i]);
    }
    ~InterruptCleanup() {
        for (int i = 0; i < 4; ++i) ::sigaction(g_signals[i], &old[i], nullptr);
    }
    InterruptCleanup(const InterruptCleanup&) = delete;
    InterruptCleanup& operator=(const InterruptCleanup&) = delete;
};

/// Holds the interrupt signals back for the lifetime of the object (delivered afterwards).
struct HoldSignals {
    sigset_t old;
    HoldSignals() {
        sigset_t s;
        sigemptyset(&s);
        for (int sig : g_signals) sigaddset(&s, sig);
        ::sigprocmask(SIG_BLOCK, &s, &old);
    }
    ~HoldSignals() { ::sigprocmask(SIG_SETMASK, &old, nullptr); }
    HoldSignals(const HoldSignals&) = delete;
    HoldSignals& operator=(const HoldSignals&) = delete;
};

bool write_all(int fd, const std::string& text, int& err) {
    const char* p = text.data();
    std::size_t left = text.size();
    while (left > 0) {
        const ssize_t n = ::write(fd, p, left);
        if (n < 0) {
            if (errno == EINTR) continue;
            err = errno;
            return false;
        }
        p += n;
        left -= static_cast<std::size_t>(n);
    }
    return true;
}

/// One file of an output set.
struct Target {
    std::string given;     // the path as given (messages)
    std::string path;      // after links
    std::string dir, base;
    const std::string* text = nullptr;
    bool special = false;  // device, FIFO, socket: written in place
    bool existed = false;
    mode_t mode = 0;       // of the existing file
    int dirfd = -1;
    int fd = -1;           // the new content (O_TMPFILE or a named temporary file)
    bool fd_unnamed = false;
    std::string temp;      // hidden name of the new content in dir ("" while unnamed)
    int temp_slot = -1;
    bool swapped = false;  // temp now holds the old content (exchanged)
    bool placed = false;   // the new content is at base
    bool remove = false;   // a stale member of the set: moved away with the set, removed after
};

unsigned g_counter = 0;

// Test hooks (tests/cli/test_cli.sh), a comma-separated list in DDEMAP_TEST_FAULT: "named"
// writes through hidden named temporary files as on a file system without O_TMPFILE; "pause"
// sleeps 30 s after the temporary files are written (a test interrupts the program there);
// "move:K" makes the move of the K-th file (1-based) of a set fail with EIO (the roll-back runs).
bool test_fault(const char* what) {
    const char* f = std::getenv("DDEMAP_TEST_FAULT");
    if (f == nullptr) return false;
    const std::string list = std::string(",") + f + ",";
    return list.find(std::string(",") + what + ",") != std::string::npos;
}
bool test_fault_move(std::size_t index) {
    const char* f = std::getenv("DDEMAP_TEST_FAULT");
    if (f == nullptr) return false;
    const char* m = std::strstr(f, "move:");
    return m != nullptr && std::strtoul(m + 5, nullptr, 10) == index + 1;
}

std::string hidden_name(const std::string& base) {
    return "." + base + ".ddemap-" + std::to_string(::getpid()) + "-" + std::to_string(++g_counter) + ".tmp";
}

/// False when no process `pid` runs: none exists, or it is a zombie (killed, not yet reaped).
bool process_alive(pid_t pid) {
    if (::kill(pid, 0) != 0) return errno != ESRCH;
    const std::string stat_path = "/proc/" + std::to_string(pid) + "/stat";
    const int fd = ::open(stat_path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return true;
    char buf[512];
    const ssize_t n = ::read(fd, buf, sizeof buf - 1);
    ::close(fd);
    if (n <= 0) return true;
    buf[n] = '\0';
    const char* paren = std::strrchr(buf, ')');  // "PID (NAME) STATE ..."
    return !(paren != nullptr && paren[1] == ' ' && paren[2] == 'Z');
}

/// The names in the folder `dirfd` (empty when it cannot be read; the fd stays open).
std::vector<std::string> folder_entries(int dirfd) {
    std::vector<std::string> names;
    const int fd = ::dup(dirfd);
    if (fd < 0) return names;
    DIR* d = ::fdopendir(fd);
    if (d == nullptr) {
        ::close(fd);
        return names;
    }
    ::rewinddir(d);
    while (const dirent* e = ::readdir(d)) names.emplace_back(e->d_name);
    ::closedir(d);
    return names;
}

/// Removes the hidden temporary files that writers killed in this folder left (SIGKILL, power
/// loss, on a file system without O_TMPFILE): every ".NAME.ddemap-PID-N.tmp" whose process PID
/// no longer exists, whatever NAME, so that the next write into the folder tidies it.
void remove_stale_temps(int dirfd) {
    const std::string mark = ".ddemap-";
    std::vector<std::string> stale;
    for (const std::string& name : folder_entries(dirfd)) {
        if (name.size() < 2 || name[0] != '.' || name.size() < mark.size() + 6 || name.compare(name.size() - 4, 4, ".tmp") != 0) continue;
        const std::size_t at = name.rfind(mark);
        if (at == std::string::npos || at == 0) continue;
        char* end = nullptr;
        const long pid = std::strtol(name.c_str() + at + mark.size(), &end, 10);
        if (pid <= 0 || end == nullptr || *end != '-') continue;
        if (!process_alive(static_cast<pid_t>(pid))) stale.push_back(name);
    }
    for (const auto& name : stale) ::unlinkat(dirfd, name.c_str(), 0);
}

std::string dir_path(const Target& t, const std::string& name) { return t.dir == "/" ? "/" + name : t.dir + "/" + name; }
// ---- the journal of an output set: completed by the next run after a SIGKILL ---------------
// A set of two or more files is moved into place one file at a time, and a SIGKILL (or a power
// loss) cannot be held back. So before the first move a journal ".ddemap-set-PID-N.journal" is
// made in every folder of the set (written and fsynced under a temporary name, then renamed:
// it exists whole or not at all). It names each file's new content by device and inode, and the
// files the set removes. After the last move and the folders' fsync the journals are removed. A
// writer killed in between leaves its journal, and the next run that writes into the folder or
// reads a file from it completes the set (complete_output_sets): every file whose entry is not
// yet the new content gets it from the hidden name holding it, every file the set removes is
// removed. A writer killed before its journal exists leaves the old set and hidden temporaries
// (remove_stale_temps).

const std::string journal_prefix = ".ddemap-set-";
const std::string journal_suffix = ".journal";

/// A field of a journal line: bytes <= ' ', '%' and DEL as %XX (file names may hold any byte).
std::string escape_field(const std::string& s) {
    static const char hex[] = "0123456789ABCDEF";
    std::string out;
    for (const char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        if (c <= 0x20 || c == '%' || c == 0x7f) {
            out += '%';
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += ch;
        }
    }
    return out;
}

bool unescape_field(const std::string& s, std::string& out) {
    out.clear();
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s[i] != '%') {
            out += s[i];
            continue;
        }
        if (i + 2 >= s.size() || !std::isxdigit(static_cast<unsigned char>(s[i + 1])) || !std::isxdigit(static_cast<unsigned char>(s[i + 2])))
            return false;
        const long v = std::strtol(s.substr(i + 1, 2).c_str(), nullptr, 16);
        out += static_cast<char>(v);
        i += 2;
    }
    return true;
}

struct JournalEntry {
    bool gone = false;  // a file the set removes (else a file the set writes)
    unsigned long long dev = 0, ino = 0;
    std::string dir, base, temp;
};

bool same_file(int dirfd, const std::string& name, const JournalEntry& e) {
    struct stat st {};
    return ::fstatat(dirfd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && static_cast<unsigned long long>(st.st_dev) == e.dev &&
           static_cast<unsigned long long>(st.st_ino) == e.ino;
}

/// Completes the set of the journal `name` in the folder `dirfd` (its writer is dead) and
/// removes its journals.
void complete_journal(int dirfd, const std::string& name) {
    std::string text;
    const int fd = ::openat(dirfd, name.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return;  // completed meanwhile by another run
    char buf[4096];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        text.append(buf, static_cast<std::size_t>(n));
    }
    ::close(fd);
    std::vector<JournalEntry> entries;
    bool whole = false;
    std::size_t pos = 0;
    while (pos < text.size()) {
        const std::size_t eol = text.find('\n', pos);
        if (eol == std::string::npos) break;
        const std::string line = text.substr(pos, eol - pos);
        pos = eol + 1;
        if (line == "end") {
            whole = true;
            break;
        }
        std::vector<std::string> f;
        for (std::size_t a = 0; a <= line.size();) {
            const std::size_t b = std::min(line.find(' ', a), line.size());
            f.push_back(line.substr(a, b - a));
            a = b + 1;
        }
        JournalEntry e;
        if (f.size() == 6 && f[0] == "new") {
            e.gone = false;
        } else if (f.size() == 5 && f[0] == "gone") {
            e.gone = true;
        } else {
            continue;  // the header line
        }
        e.dev = std::strtoull(f[1].c_str(), nullptr, 10);
        e.ino = std::strtoull(f[2].c_str(), nullptr, 10);
        if (!unescape_field(f[3], e.dir) || !unescape_field(f[4], e.base) || (!e.gone && !unescape_field(f[5], e.temp))) continue;
        entries.push_back(e);
    }
    if (whole) {
        for (const JournalEntry& e : entries) {
            const int d = ::open(e.dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
            if (d < 0) continue;
            if (e.gone) {
                if (same_file(d, e.base, e)) ::unlinkat(d, e.base.c_str(), 0);
            } else if (!same_file(d, e.base, e) && same_file(d, e.temp, e)) {
                ::renameat(d, e.temp.c_str(), d, e.base.c_str());
            }
            ::fsync(d);
            ::close(d);
        }
    }
    // every folder's copy of this journal (the same name), then this one
    for (const JournalEntry& e : entries) {
        const int d = ::open(e.dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (d < 0) continue;
        ::unlinkat(d, name.c_str(), 0);
        ::close(d);
    }
    ::unlinkat(dirfd, name.c_str(), 0);
}

/// Completes every output set in the folder `dirfd` whose writer was killed (see above).
void complete_output_sets(int dirfd) {
    std::vector<std::string> dead;
    for (const std::string& name : folder_entries(dirfd)) {
        if (name.size() <= journal_prefix.size() + journal_suffix.size() || name.compare(0, journal_prefix.size(), journal_prefix) != 0 ||
            name.compare(name.size() - journal_suffix.size(), journal_suffix.size(), journal_suffix) != 0)
            continue;
        char* end = nullptr;
        const long pid = std::strtol(name.c_str() + journal_prefix.size(), &end, 10);
        if (pid <= 0 || end == nullptr || *end != '-') continue;
        if (!process_alive(static_cast<pid_t>(pid))) dead.push_back(name);
    }
    for (const auto& name : dead) complete_journal(dirfd, name);
}


void close_all(std::vector<Target>& ts) {
    for (auto& t : ts) {
        if (t.fd >= 0) ::close(t.fd);
        if (t.dirfd >= 0) ::close(t.dirfd);
        t.fd = t.dirfd = -1;
    }
}

/// Removes the named temporary files (and unregisters them).
void remove_temps(std::vector<Target>& ts) {
    for (auto& t : ts) {
        if (!t.temp.empty() && t.dirfd >= 0) ::unlinkat(t.dirfd, t.temp.c_str(), 0);
        unregister_named(t.temp_slot);
        t.temp_slot = -1;
        t.temp.clear();
    }
}

[[noreturn]] void fail(std::vector<Target>& ts, const std::string& path, int err, const std::string& what = "cannot write") {
    remove_temps(ts);
    close_all(ts);
    throw WriteError(what + " " + path + ": " + reason(err));
}

/// Gives the new content of `t` a hidden name in its folder (for the move into place).
bool name_temp(Target& t, int& err) {
    if (!t.fd_unnamed) return true;
    const std::string proc = "/proc/self/fd/" + std::to_string(t.fd);
    for (int attempt = 0; attempt < 100; ++attempt) {
        const std::string name = hidden_name(t.base);
        const int slot = register_named(dir_path(t, name));
        if (::linkat(AT_FDCWD, proc.c_str(), t.dirfd, name.c_str(), AT_SYMLINK_FOLLOW) == 0) {
            t.temp = name;
            t.temp_slot = slot;
            return true;
        }
        err = errno;
        unregister_named(slot);
        if (err != EEXIST) return false;
    }
    return false;
}

/// The journals of a set of two or more regular files (see complete_journal), one per folder,
/// each complete and fsynced before it appears under its name; their (folder fd, name) in
/// `made`. False (errno in `err`) when one cannot be made: nothing has been moved yet.
bool write_journals(const std::vector<Target>& ts, std::vector<std::pair<int, std::string>>& made, int& err) {
    std::string text = "ddemap output set 1\n";
    std::vector<std::pair<std::string, int>> dirs;  // absolute folder, its fd
    for (const Target& t : ts) {
        if (t.special) continue;
        char abs[PATH_MAX];
        if (::realpath(t.dir.c_str(), abs) == nullptr) {
            err = errno;
            return false;
        }
        struct stat st {};
        const int rc = t.remove ? ::fstatat(t.dirfd, t.base.c_str(), &st, AT_SYMLINK_NOFOLLOW) : ::fstat(t.fd, &st);
        if (rc != 0) {
            err = errno;
            return false;
        }
        text += std::string(t.remove ? "gone " : "new ") + std::to_string(static_cast<unsigned long long>(st.st_dev)) + " " +
                std::to_string(static_cast<unsigned long long>(st.st_ino)) + " " + escape_field(abs) + " " + escape_field(t.base);
        text += t.remove ? "\n" : " " + escape_field(t.temp) + "\n";
        bool seen = false;
        for (const auto& d : dirs) seen = seen || d.first == abs;
        if (!seen) dirs.emplace_back(abs, t.dirfd);
    }
    text += "end\n";
    const std::string name = journal_prefix + std::to_string(::getpid()) + "-" + std::to_string(++g_counter) + journal_suffix;
    for (const auto& d : dirs) {
        const std::string temp = hidden_name("ddemap-set");
        const int fd = ::openat(d.second, temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        if (fd < 0) {
            err = errno;
            return false;
        }
        bool ok = write_all(fd, text, err) && (::fsync(fd) == 0 || ((err = errno), false));
        ::close(fd);
        if (ok && ::renameat(d.second, temp.c_str(), d.second, name.c_str()) != 0) {
            err = errno;
            ok = false;
        }
        if (!ok) {
            ::unlinkat(d.second, temp.c_str(), 0);
            return false;
        }
        made.emplace_back(d.second, name);
        if (::fsync(d.second) != 0 && errno != EINVAL) {
            err = errno;
            return false;
        }
    }
    return true;
}

void remove_journals(std::vector<std::pair<int, std::string>>& made) {
    for (const auto& j : made) ::unlinkat(j.first, j.second.c_str(), 0);
    made.clear();
}

}  // namespace

std::string normalize_input_text(std::string text) {
    if (text.size() >= 3 && static_cast<unsigned char>(text[0]) == 0xEF && static_cast<unsigned char>(text[1]) == 0xBB &&
        static_cast<unsigned char>(text[2]) == 0xBF)
        text.erase(0, 3);
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') continue;
        out += text[i];
    }
    if (!out.empty() && out.back() == '\r') out.pop_back();
    return out;
}

namespace {

/// The regular files this process has read (device and inode): an output never replaces one
/// (`classify mycars.csv --out mycars` would otherwise write its table over the cars).
std::vector<std::pair<dev_t, ino_t>>& inputs_read() {
    static std::vector<std::pair<dev_t, ino_t>> files;
    return files;
}

/// std::invalid_argument when `path` is a file this process has read.
void refuse_input(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
    for (const auto& f : inputs_read())
        if (f.first == st.st_dev && f.second == st.st_ino)
            throw std::invalid_argument("'" + path + "' is an input of this command: expected another output name (it would be overwritten)");
}

}  // namespace

std::string read_text_file(const std::string& path) {
    complete_interrupted_output_sets(dir_of(path));  // a set a killed writer left is read whole
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw std::invalid_argument("'" + path + "': cannot open the file (" + reason(errno) + ")");
    if (S_ISDIR(st.st_mode)) throw std::invalid_argument("'" + path + "' is a folder, expected a file");
    if (S_ISREG(st.st_mode)) inputs_read().emplace_back(st.st_dev, st.st_ino);
    // a bound on what is read: a regular file by its size, a stream (a device such as /dev/zero,
    // a pipe) while it is read, so that an endless one is refused instead of read for ever
    constexpr std::size_t kMaxInputBytes = std::size_t(1) << 30;
    const std::string too_large = "'" + path + "': more than 1 GB of text: expected an input file of at most 1 GB";
    if (S_ISREG(st.st_mode) && static_cast<unsigned long long>(st.st_size) > kMaxInputBytes) throw std::invalid_argument(too_large);
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw std::invalid_argument("'" + path + "': cannot open the file (" + reason(errno) + ")");
    std::string text;
    char buf[65536];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0) {
            if (errno == EINTR) continue;
            const int err = errno;
            ::close(fd);
            throw std::invalid_argument("'" + path + "': cannot read the file (" + reason(err) + ")");
        }
        if (n == 0) break;
        if (text.size() + static_cast<std::size_t>(n) > kMaxInputBytes) {
            ::close(fd);
            throw std::invalid_argument(too_large);
        }
        text.append(buf, static_cast<std::size_t>(n));
    }
    ::close(fd);
    text = normalize_input_text(std::move(text));
    detail::require_utf8(text, path);  // names go into JSON, CSV and SVG: refused here, before any work
    return text;
}

std::string resolve_output_path(const std::string& path) {
    std::string p = path;
    for (int hops = 0; hops < 40; ++hops) {
        struct stat st {};
        if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
        std::string link(PATH_MAX, '\0');
        const ssize_t n = ::readlink(p.c_str(), &link[0], link.size());
        if (n <= 0) return p;
        link.resize(static_cast<std::size_t>(n));
        p = link[0] == '/' ? link : (dir_of(p) == "." && p.find('/') == std::string::npos ? link : dir_of(p) + "/" + link);
    }
    throw std::invalid_argument("'" + path + "': too many levels of symbolic links");
}

void check_output_file(const std::string& given) {
    const std::string path = resolve_output_path(given);
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) throw std::invalid_argument("'" + given + "' is a folder, expected a file to write");
        if (!S_ISREG(st.st_mode)) {
            if (::access(path.c_str(), W_OK) != 0) throw std::invalid_argument("'" + given + "' is not writable (" + reason(errno) + ")");
            return;
        }
    }
    // the folder: every existing part must be a folder
    const std::string dir = dir_of(path);
    std::string part;
    std::size_t pos = 0;
    while (pos != std::string::npos) {
        const auto next = dir.find('/', pos + 1);
        part = dir.substr(0, next);
        pos = next;
        if (part.empty()) continue;
        struct stat ds {};
        if (::stat(part.c_str(), &ds) != 0) {
            if (errno == ENOENT) throw std::invalid_argument("'" + given + "': the folder '" + part + "' does not exist");
            throw std::invalid_argument("'" + given + "': the folder '" + part + "' cannot be used (" + reason(errno) + ")");
        }
        if (!S_ISDIR(ds.st_mode)) throw std::invalid_argument("'" + given + "': '" + part + "' is a file, not a folder");
    }
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw std::invalid_argument("'" + given + "': the folder '" + dir + "' is not writable (" + reason(errno) + ")");
    // access() answers from the permission bits, and yes for root: a file made and dropped in
    // the folder proves it (a folder of /proc, a file system that refuses new files), before
    // the work rather than after it
    const std::string probe = (dir.empty() ? std::string(".") : dir) + "/" + hidden_name("probe");
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) throw std::invalid_argument("'" + given + "': the folder '" + dir + "' is not writable (" + reason(errno) + ")");
    ::close(fd);
    ::unlink(probe.c_str());
}

void complete_interrupted_output_sets(const std::string& folder) {
    const int fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    complete_output_sets(fd);
    remove_stale_temps(fd);
    ::close(fd);
}

void write_file_atomic(const std::string& path, const std::string& text) { write_files_atomic({{path, text}}); }

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files, const std::vector<std::string>& remove) {
    static const std::string nothing;
    std::vector<Target> ts(files.size() + remove.size());
    for (std::size_t i = files.size(); i < ts.size(); ++i) {
        ts[i].remove = true;
        ts[i].given = remove[i - files.size()];
        ts[i].text = &nothing;
    }
    // 0. no file of the set is an input of this process (before anything is written)
    for (const auto& f : files) {
        std::string path;
        try {
            path = resolve_output_path(f.first);
        } catch (const std::invalid_argument&) {
            continue;  // a link loop: refused below with the others
        }
        refuse_input(path);
    }
    InterruptCleanup cleanup;
    // 1. resolve every path; write the special files; write the regular ones to temporary files
    for (std::size_t i = 0; i < ts.size(); ++i) {
        Target& t = ts[i];
        if (!t.remove) {
            t.given = files[i].first;
            t.text = &files[i].second;
        }
        try {
            t.path = resolve_output_path(t.given);
        } catch (const std::invalid_argument&) {
            fail(ts, t.given, ELOOP);
        }
        t.dir = dir_of(t.path);
        t.base = base_of(t.path);
        struct stat st {};
        if (t.remove) {  // only a regular file is removed (a folder or a device is left alone)
            t.existed = ::stat(t.path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
            t.special = !t.existed;
            continue;
        }
        if (::stat(t.path.c_str(), &st) == 0) {
            if (S_ISDIR(st.st_mode)) fail(ts, t.given, EISDIR);
            t.special = !S_ISREG(st.st_mode);
            t.existed = true;
            t.mode = st.st_mode & 07777;
        }
    }
    for (auto& t : ts) {
        if (!t.special || t.remove) continue;
        const int fd = ::open(t.path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
        if (fd < 0) fail(ts, t.given, errno);
        int err = 0;
        const bool ok = write_all(fd, *t.text, err);
        if (ok && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) err = errno;
        if (::close(fd) != 0 && ok && err == 0 && errno != EINTR) err = errno;
        if (!ok || err != 0) fail(ts, t.given, err);
    }
    for (auto& t : ts) {
        if (t.special) continue;
        t.dirfd = ::open(t.dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (t.dirfd < 0) fail(ts, t.given, errno);
        complete_output_sets(t.dirfd);  // before the stale temporaries go: they may hold a set's new files
        remove_stale_temps(t.dirfd);
        if (t.remove) continue;
        const mode_t mode = t.existed ? t.mode : 0666;
        t.fd = test_fault("named") ? -1 : ::openat(t.dirfd, ".", O_TMPFILE | O_WRONLY | O_CLOEXEC, mode);
        t.fd_unnamed = t.fd >= 0;
        if (t.fd < 0) {  // no O_TMPFILE on this file system: a hidden named file, removed on interrupt
            for (int attempt = 0; attempt < 100 && t.fd < 0; ++attempt) {
                const std::string name = hidden_name(t.base);
                const int slot = register_named(dir_path(t, name));
                t.fd = ::openat(t.dirfd, name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
                if (t.fd >= 0) {
                    t.temp = name;
                    t.temp_slot = slot;
                } else {
                    const int err = errno;
                    unregister_named(slot);
                    if (err != EEXIST) fail(ts, t.given, err);
                }
            }
            if (t.fd < 0) fail(ts, t.given, EEXIST);
        }
        if (t.existed) ::fchmod(t.fd, t.mode);  // the umask does not narrow an existing file's mode
        int err = 0;
        if (!write_all(t.fd, *t.text, err)) fail(ts, t.given, err);
        if (::fsync(t.fd) != 0) fail(ts, t.given, errno);
    }
    if (test_fault("pause")) ::sleep(30);
    // 2. move every file into place with the interrupts held back; roll back on a failure
    HoldSignals hold;
    for (auto& t : ts) {
        if (t.special) continue;
        int err = 0;
        if (!name_temp(t, err)) fail(ts, t.given, err);
    }
    // two or more files: a journal first, so that a SIGKILL among the moves is completed later
    std::vector<std::pair<int, std::string>> journals;
    std::size_t regular = 0;
    for (const auto& t : ts) regular += t.special ? 0 : 1;
    if (regular >= 2) {
        int err = 0;
        if (!write_journals(ts, journals, err)) {
            remove_journals(journals);
            fail(ts, ts.front().given, err);
        }
    }
    for (std::size_t i = 0; i < ts.size(); ++i) {
        Target& t = ts[i];
        if (t.special) continue;
        int rc = -1, err = 0;
        if (test_fault_move(i)) {
            rc = -1;
            errno = EIO;
        } else if (t.remove) {  // moved away to a hidden name, removed after the set is in place
            for (int attempt = 0; attempt < 100; ++attempt) {
                const std::string name = hidden_name(t.base);
                const int slot = register_named(dir_path(t, name));
                rc = ::renameat2(t.dirfd, t.base.c_str(), t.dirfd, name.c_str(), RENAME_NOREPLACE);
                if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) rc = ::renameat(t.dirfd, t.base.c_str(), t.dirfd, name.c_str());
                if (rc == 0) {
                    t.temp = name;
                    t.temp_slot = slot;
                    break;
                }
                err = errno;
                unregister_named(slot);
                if (err != EEXIST) break;
            }
            if (rc == 0) {
                t.placed = t.swapped = true;
                continue;
            }
            errno = err;
        } else if (t.existed) {
            rc = ::renameat2(t.dirfd, t.temp.c_str(), t.dirfd, t.base.c_str(), RENAME_EXCHANGE);
            if (rc == 0) t.swapped = true;
            else if (errno == EINVAL || errno == ENOSYS) rc = ::renameat(t.dirfd, t.temp.c_str(), t.dirfd, t.base.c_str());
        } else {
            rc = ::renameat2(t.dirfd, t.temp.c_str(), t.dirfd, t.base.c_str(), RENAME_NOREPLACE);
            if (rc != 0 && (errno == EINVAL || errno == ENOSYS)) rc = ::renameat(t.dirfd, t.temp.c_str(), t.dirfd, t.base.c_str());
        }
        if (rc != 0) err = errno;
        if (rc == 0) {
            t.placed = true;
            if (!t.swapped) {  // the temporary name is gone
                unregister_named(t.temp_slot);
                t.temp_slot = -1;
                t.temp.clear();
            }
            continue;
        }
        // roll back the files already moved: the old content back in place, new files removed
        for (std::size_t j = 0; j < i; ++j) {
            Target& u = ts[j];
            if (!u.placed) continue;
            if (u.remove) ::renameat(u.dirfd, u.temp.c_str(), u.dirfd, u.base.c_str());
            else if (u.swapped) ::renameat2(u.dirfd, u.temp.c_str(), u.dirfd, u.base.c_str(), RENAME_EXCHANGE);
            else if (!u.existed) ::unlinkat(u.dirfd, u.base.c_str(), 0);
        }
        remove_journals(journals);
        fail(ts, t.given, err);
    }
    int err = 0;
    std::string bad;
    for (auto& t : ts) {
        if (t.special || t.dirfd < 0) continue;
        if (::fsync(t.dirfd) != 0 && err == 0 && errno != EINVAL) {
            err = errno;
            bad = t.given;
        }
    }
    remove_journals(journals);  // the set is in place: nothing is left to complete
    remove_temps(ts);           // the old contents
    close_all(ts);
    if (err != 0) throw WriteError("cannot write " + bad + ": " + reason(err));
}

}  // namespace ddemap
