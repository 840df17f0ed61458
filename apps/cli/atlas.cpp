// atlas: the sweep's quantities over a grid of up to five parameters and ring sizes (a TOML spec),
// in chunks over OpenMP threads and, under mpirun, MPI ranks; HDF5 and a figure in DIR; resumable.
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include <sys/stat.h>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "ddemap/io/atlas.hpp"
#include "ddemap/io/files.hpp"

#if DDEMAP_WITH_MPI
#include <mpi.h>
#endif

namespace ddemap::cli {

namespace {
struct AtlasArgs {
    std::string spec;
    OutArg out;
    bool resume = false;
} atlas_args;

/// The chunks of one run: those still to compute, handed out in order; the results appended
/// to the chunk store as they arrive (rank 0 keeps no values in memory). Thread-safe.
class Ledger {
public:
    Ledger(const AtlasSpec& spec, AtlasStore& store, std::vector<char>& done, Progress progress)
        : m_spec(spec), m_store(store), m_done(done), m_progress(std::move(progress)) {
        for (long c = 0; c < spec.chunks(); ++c)
            if (!done[static_cast<std::size_t>(c)]) m_queue.push_back(c);
        m_pending = static_cast<long>(m_queue.size());
    }
    long pending() const { return m_pending; }
    /// The next chunk to compute, or -1 when none is left (or a failure stopped the run).
    long next() {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (m_queue.empty() || m_failed) return -1;
        const long c = m_queue.front();
        m_queue.pop_front();
        return c;
    }
    /// Stores a finished chunk (its values, in the chunk store).
    void finish(long c, const double* v, std::size_t count) {
        std::lock_guard<std::mutex> lock(m_mutex);
        const std::size_t nf = atlas_fields().size();
        const std::size_t expect = static_cast<std::size_t>(m_spec.chunk_end(c) - m_spec.chunk_begin(c)) * nf;
        if (c < 0 || c >= m_spec.chunks() || count != expect || m_done[static_cast<std::size_t>(c)])
            throw std::logic_error("atlas: a result for chunk " + std::to_string(c) + " of unexpected size or twice");
        try {
            m_store.append(c, v, count);
        } catch (...) {
            m_failed = true;
            throw;
        }
        m_done[static_cast<std::size_t>(c)] = 1;
        ++m_finished;
        if (m_progress) m_progress(m_finished, m_pending);
    }
    /// Every chunk of the run stored.
    bool complete() {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_finished == m_pending;
    }
    void fail() {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_failed = true;
    }

private:
    const AtlasSpec& m_spec;
    AtlasStore& m_store;
    std::vector<char>& m_done;
    Progress m_progress;
    std::mutex m_mutex;
    std::deque<long> m_queue;
    long m_pending = 0, m_finished = 0;
    bool m_failed = false;
};

/// `threads` workers (OpenMP through parallel_for), each taking chunks from the ledger until
/// none is left.
void compute_locally(const AtlasSpec& spec, Ledger& ledger, int threads) {
    ExecutionPolicy policy;
    policy.threads = threads;
    parallel_for(threads, [&](long) {
        try {
            for (long c = ledger.next(); c >= 0; c = ledger.next()) {
                const std::vector<double> v = evaluate_atlas_chunk(spec, c);
                ledger.finish(c, v.data(), v.size());
            }
        } catch (...) {
            ledger.fail();  // the other workers stop after their current chunk
            throw;
        }
    }, policy);
}

/// Refuses an atlas above the limits before any work. Memory on rank 0: the chunk store's
/// index, the queue of chunks and the done flags (17 bytes per chunk), a chunk's values per thread (twice: computed
/// and its record; 128 bytes per point each), the HDF5 slab (65536 points x 16 doubles, and one
/// field's copy: 9 MB), the figure's points (at most 250,000 sweep points: 30 MB), and HDF5's
/// caches (a few MB). Output: 88 bytes of HDF5 per point (9 float64, 3 int32, 4 flags) and,
/// while it runs, the chunk store (128 bytes per point). Time: 5e-5 s per ring mode on one
/// core (the sweep's measured cost; N = inf and the winding path about 12 modes at any N).
void check_atlas_size(const AtlasSpec& spec, int workers) {
    const bool winding = spec.ring_method_used() == "winding";
    double modes = 0.0;
    for (int n : spec.rings) modes += n == 0 || winding ? 12.0 : n / 2 + 1.0;
    const double per_ring = static_cast<double>(spec.points()) / static_cast<double>(spec.rings.size());
    const double chunk_bytes = static_cast<double>(spec.chunk_size()) * 128.0;
    std::ostringstream what;
    what << "an atlas of " << spec.points() << " points";
    check_size("atlas", what.str(), "memory", 17.0 * static_cast<double>(spec.chunks()) + 2.0 * chunk_bytes * (workers + 1) + 5e7);
    check_size("atlas", what.str(), "output", static_cast<double>(spec.points()) * (88.0 + 128.0));
    check_size("atlas", what.str(), "time", per_ring * modes * 5e-5 / std::max(1, workers));
}

struct Outcome {
    long computed = 0, loaded = 0;
    double seconds = 0.0;
};

#if DDEMAP_WITH_MPI
constexpr int tag_request = 1, tag_assign = 2, tag_result = 3;
/// Requests each rank > 0 keeps outstanding: one batch is always waiting at the rank while it
/// computes another, whatever the delay of rank 0's answer (its coordinator polls, and on a
/// loaded machine waits for a core).
constexpr int lookahead = 2;

/// Rank 0 of an MPI run: hands out chunks on request (as many as the asking rank has threads)
/// and stores the results, while its own threads compute chunks from the same ledger.
void coordinate(const AtlasSpec& spec, Ledger& ledger, int ranks, int threads) {
    std::atomic<bool> local_done{false};
    std::exception_ptr local_error;
    std::thread local([&] {
        try {
            compute_locally(spec, ledger, threads);
        } catch (...) {
            local_error = std::current_exception();
        }
        local_done = true;
    });
    int active = lookahead * (ranks - 1);  // requests that will still be answered with none
    std::vector<double> buffer;
    try {
        // until every rank was told to stop and every chunk is stored (a rank asks for its next
        // chunks before it sends the results of the current ones: results may still arrive
        // after its last answer); a failure of the local threads ends the wait for results
        while (active > 0 || (!ledger.complete() && !(local_done && local_error))) {
            int flag = 0;
            MPI_Status st;
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
            if (!flag) {
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
                continue;
            }
            if (st.MPI_TAG == tag_request) {
                int want = 0;
                MPI_Recv(&want, 1, MPI_INT, st.MPI_SOURCE, tag_request, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                std::vector<long long> chunks;
                for (int i = 0; i < std::max(1, want); ++i) {
                    const long c = ledger.next();
                    if (c < 0) break;
                    chunks.push_back(c);
                }
                MPI_Send(chunks.data(), static_cast<int>(chunks.size()), MPI_LONG_LONG, st.MPI_SOURCE, tag_assign, MPI_COMM_WORLD);
                if (chunks.empty()) --active;  // one of that rank's request streams stops
            } else if (st.MPI_TAG == tag_result) {
                int count = 0;
                MPI_Get_count(&st, MPI_DOUBLE, &count);
                buffer.resize(static_cast<std::size_t>(std::max(count, 1)));
                MPI_Recv(buffer.data(), count, MPI_DOUBLE, st.MPI_SOURCE, tag_result, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                if (count < 1) throw std::logic_error("atlas: an empty result message");
                ledger.finish(static_cast<long>(buffer[0]), buffer.data() + 1, static_cast<std::size_t>(count - 1));
            } else {
                throw std::logic_error("atlas: a message with an unknown tag");
            }
        }
    } catch (...) {
        ledger.fail();
        local.join();
        throw;
    }
    local.join();
    if (local_error) std::rethrow_exception(local_error);
}

/// The chunks rank 0 assigns to this rank (empty: stop).
std::vector<long long> receive_assignment() {
    MPI_Status st;
    MPI_Probe(0, tag_assign, MPI_COMM_WORLD, &st);
    int count = 0;
    MPI_Get_count(&st, MPI_LONG_LONG, &count);
    std::vector<long long> chunks(static_cast<std::size_t>(std::max(count, 1)));
    MPI_Recv(chunks.data(), count, MPI_LONG_LONG, 0, tag_assign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    chunks.resize(static_cast<std::size_t>(count));
    return chunks;
}

/// A rank > 0: asks rank 0 for chunks (as many as it has threads), computes them, sends the
/// values back (the chunk index first), until rank 0 answers with none. The request for the
/// next chunks goes out before the current ones are computed, so that the answer is there when
/// they are done (no idle round trip to rank 0); the values go out without waiting (MPI_Isend:
/// a chunk's message is above the eager limit, and a blocking send would wait until rank 0's
/// coordinator, which polls, takes it) while the next chunks are computed.
void serve(const AtlasSpec& spec, int threads) {
    std::vector<std::vector<double>> sending;  // the previous batch's messages, in flight
    std::vector<MPI_Request> requests;
    for (int i = 0; i < lookahead; ++i) MPI_Send(&threads, 1, MPI_INT, 0, tag_request, MPI_COMM_WORLD);
    // each non-empty answer is followed by one new request, so `lookahead` stay outstanding; the
    // answers come in order, and once one is empty the ledger is empty: the others are too
    int open = lookahead;
    for (std::vector<long long> chunks = receive_assignment(); !chunks.empty(); chunks = receive_assignment()) {
        MPI_Send(&threads, 1, MPI_INT, 0, tag_request, MPI_COMM_WORLD);
        const int count = static_cast<int>(chunks.size());
        std::vector<std::vector<double>> results(static_cast<std::size_t>(count));
        ExecutionPolicy policy;
        policy.threads = threads;
        parallel_for(count, [&](long i) {
            const std::vector<double> v = evaluate_atlas_chunk(spec, static_cast<long>(chunks[static_cast<std::size_t>(i)]));
            std::vector<double>& r = results[static_cast<std::size_t>(i)];
            r.reserve(v.size() + 1);
            r.push_back(static_cast<double>(chunks[static_cast<std::size_t>(i)]));
            r.insert(r.end(), v.begin(), v.end());
        }, policy);
        MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
        sending = std::move(results);
        requests.assign(sending.size(), MPI_REQUEST_NULL);
        for (std::size_t i = 0; i < sending.size(); ++i)
            MPI_Isend(sending[i].data(), static_cast<int>(sending[i].size()), MPI_DOUBLE, 0, tag_result, MPI_COMM_WORLD, &requests[i]);
    }
    for (--open; open > 0; --open) receive_assignment();  // the other outstanding answers (empty)
    MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
}

#endif

/// True when started by mpirun (OpenMPI or a PMI launcher): only then is MPI initialised, so the
/// program runs as before without mpirun.
bool under_mpirun() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"})
        if (std::getenv(v)) return true;
    return false;
}

}  // namespace

void add_atlas_flags(CLI::App& app) {
    app.add_option("spec", atlas_args.spec, "the atlas spec (TOML, see maps/atlas-example.toml)")->required();
    app.add_option("--out", atlas_args.out.text, "the folder of DIR/atlas.h5, DIR/atlas.svg (and DIR/atlas.chunks while it runs)")
        ->required()
        ->type_name("DIR");
    app.add_flag("--resume", atlas_args.resume, "continue an interrupted run from the chunks finished in DIR/atlas.chunks");
    run_flags().add_to(app, true);
}

int run_atlas() {
    int rank = 0, ranks = 1;
#if DDEMAP_WITH_MPI
    const bool mpi = under_mpirun();
    if (mpi) {
        int provided = 0;
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    }
    // every rank ends through here: MPI_Finalize after a normal end; on an error rank 0 reports
    // (main prints the message) and every other rank stops with it
    struct Finalize {
        bool on;
        ~Finalize() {
            if (on) MPI_Finalize();
        }
    } finalize{mpi};
#else
    // without MPI, every process under mpirun would compute and write the whole atlas alone
    const char* world = std::getenv("OMPI_COMM_WORLD_SIZE");
    if (under_mpirun() && world && std::atoi(world) > 1)
        throw BadInput("this ddemap was built without MPI (DDEMAP_WITH_MPI=OFF): run `ddemap atlas` without mpirun, or build with MPI");
#endif
    const auto t0 = std::chrono::steady_clock::now();
    // rank 0 reads the spec and sends its text to the others (which need no copy of the file)
    std::string text;
    std::exception_ptr read_error;
    if (rank == 0) {
        try {
            text = read_input_file("spec", atlas_args.spec);
        } catch (...) {
            read_error = std::current_exception();
        }
    }
#if DDEMAP_WITH_MPI
    if (ranks > 1) {
        int ok = read_error ? 0 : 1;
        MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
        if (!ok && rank > 0) return exit_bad_input;
    }
#endif
    if (read_error) std::rethrow_exception(read_error);
#if DDEMAP_WITH_MPI
    if (ranks > 1) {
        long long size = static_cast<long long>(text.size());
        MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
        text.resize(static_cast<std::size_t>(size));
        MPI_Bcast(&text[0], static_cast<int>(size), MPI_CHAR, 0, MPI_COMM_WORLD);
    }
#endif
    // every rank parses the same text: a bad spec ends every rank alike (rank 0 reports)
    AtlasFile file;
    try {
        file = parse_atlas_spec(text, atlas_args.spec);
    } catch (const std::invalid_argument&) {
        if (rank == 0) throw;
        return exit_bad_input;
    }
    const AtlasSpec& spec = file.spec;
    const int threads = thread_count();

    // rank 0: the size guard, the output folder and the chunk store, before any work
    std::string prefix;
    std::vector<char> done;
    std::unique_ptr<AtlasStore> store;
    std::exception_ptr setup_error;
    bool complete = false;
    if (rank == 0) {
        try {
            check_atlas_size(spec, threads * ranks);
            OutArg dir;
            dir.text = atlas_args.out.text.empty() || atlas_args.out.text.back() == '/' ? atlas_args.out.text : atlas_args.out.text + "/";
            prefix = dir.prepare("atlas", {".h5", ".svg", ".chunks"});
            // --resume of a run that had finished: nothing to do (the store went with the result)
            struct stat st {};
            const bool store_exists = ::stat((prefix + ".chunks").c_str(), &st) == 0;
            if (atlas_args.resume && !store_exists && atlas_hdf5_matches(prefix + ".h5", text)) {
                complete = true;
            } else {
                if (!atlas_args.resume && store_exists && !run_flags().quiet)
                    std::cerr << "ddemap: atlas: note: the chunks of an earlier run in " << prefix
                              << ".chunks are discarded (--resume continues that run)\n";
                store = std::make_unique<AtlasStore>(prefix + ".chunks", spec, atlas_fingerprint(text), atlas_args.resume, done);
            }
        } catch (...) {
            setup_error = std::current_exception();
        }
    }
#if DDEMAP_WITH_MPI
    if (ranks > 1) {
        int state = setup_error ? 0 : complete ? 2 : 1;  // 0: refused, 1: run, 2: nothing to do
        MPI_Bcast(&state, 1, MPI_INT, 0, MPI_COMM_WORLD);
        if (state == 0 && rank > 0) return exit_bad_input;
        if (state == 2 && rank > 0) return exit_ok;
    }
#endif
    if (setup_error) std::rethrow_exception(setup_error);
    if (complete) {
        std::cout << "atlas      " << prefix << ".h5 is complete for this spec: nothing to compute\n";
        return exit_ok;
    }

#if DDEMAP_WITH_MPI
    if (rank > 0) {
        try {
            serve(spec, threads);
        } catch (const std::exception& e) {
            std::cerr << "ddemap: internal error: rank " << rank << ": " << e.what() << "\n";
            MPI_Abort(MPI_COMM_WORLD, exit_internal);
        }
        return exit_ok;
    }
#endif
    const long loaded = store->loaded();
    if (atlas_args.resume && !run_flags().quiet) {
        std::cerr << "ddemap: atlas: resumed " << loaded << " of " << spec.chunks() << " chunks from " << prefix << ".chunks";
        if (store->dropped_bytes() > 0) std::cerr << " (a torn last record of " << store->dropped_bytes() << " bytes dropped)";
        std::cerr << "\n";
    }
    long computed_points = 0;
    for (long c = 0; c < spec.chunks(); ++c)
        if (!done[static_cast<std::size_t>(c)]) computed_points += spec.chunk_end(c) - spec.chunk_begin(c);
    Ledger ledger(spec, *store, done, progress_printer("atlas", "chunks"));
    const long computed = ledger.pending();
    const auto t_compute = std::chrono::steady_clock::now();
#if DDEMAP_WITH_MPI
    if (ranks > 1) {
        try {
            coordinate(spec, ledger, ranks, threads);
        } catch (const WriteError& e) {
            std::cerr << "ddemap: error: " << e.what() << "\n";
            MPI_Abort(MPI_COMM_WORLD, exit_write_failed);
        } catch (const std::exception& e) {
            std::cerr << "ddemap: internal error: " << e.what() << "\n";
            MPI_Abort(MPI_COMM_WORLD, exit_internal);
        }
    } else {
        compute_locally(spec, ledger, threads);
    }
#else
    compute_locally(spec, ledger, threads);
#endif
    const double compute_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_compute).count();
    store->sync();
    const std::string svg = atlas_svg(file, store->reader());
    const std::size_t nf = atlas_fields().size();
    long classes[4] = {0, 0, 0, 0}, uncertified = 0;
    {
        std::vector<double> v(static_cast<std::size_t>(spec.chunk_size()) * nf);
        for (long c = 0; c < spec.chunks(); ++c) {
            store->read(c, v.data());
            for (long i = 0; i < spec.chunk_end(c) - spec.chunk_begin(c); ++i) {
                ++classes[static_cast<int>(v[static_cast<std::size_t>(i) * nf + 15])];
                uncertified += v[static_cast<std::size_t>(i) * nf + 14] == 0.0;
            }
        }
    }
    // the HDF5 file from the chunk store in slabs (bounded memory at any size), through
    // DIR/atlas.h5.part, in place while the store still holds every chunk (a crash here leaves a
    // store that --resume completes without computing); then the figure, with the store removed
    write_atlas_hdf5(prefix + ".h5", spec, store->reader(), text);
    store.reset();
    write_files_atomic({{prefix + ".svg", svg}}, {prefix + ".chunks"});
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::ostringstream out;
    out << "atlas      " << spec.points() << " points in " << spec.chunks() << " chunks of " << spec.chunk_size() << " (" << computed
        << " computed, " << loaded << " resumed) in " << rounded(seconds, 3) << " s";
    if (computed > 0) {
        out << " (" << static_cast<long>(std::lround(computed_points / std::max(compute_seconds, 1e-9))) << " points/s";
        out << ", " << ranks << (ranks == 1 ? " process" : " processes") << " x " << threads << (threads == 1 ? " thread" : " threads")
            << ", ring method " << spec.ring_method_used() << ")";
    }
    out << "\nregions    plant unstable " << classes[0] << ", ring unstable " << classes[1] << ", string unstable " << classes[2]
        << ", string stable " << classes[3];
    if (uncertified > 0) out << " (" << uncertified << " of them UNDECIDED: no certificate)";
    out << "\nwrote      " << prefix << ".h5 " << prefix << ".svg\n";
    std::cout << out.str();
    if (uncertified > 0) {
        std::cerr << "ddemap: atlas undecided (uncertified): " << counted(uncertified, "point") << (uncertified == 1 ? " has" : " have")
                  << " no certificate even after collocation (see the 'certified' dataset)\n";
        return exit_not_converged;
    }
    return exit_ok;
}

}  // namespace ddemap::cli
