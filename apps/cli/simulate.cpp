// simulate: a nonlinear platoon behind a lead speed profile.
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "lead_flags.hpp"
#include "limits.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct SimulateArgs {
    std::string fleet, on_event = "continue", t_end = "0", step = "0.05", output_dt = "0.1", noise, seed = "1";
    LeadArgs lead;
    FormatArg format;
    OutArg out;
} simulate_args;
}  // namespace

void add_simulate_flags(CLI::App& app) {
    app.add_option("--fleet", simulate_args.fleet, std::string("the followers in platoon order (the first follows the lead): ") + cars_help() +
                                                       "; every car of the ovrv law")
        ->type_name("CARS");
    simulate_args.lead.add_to(app);
    simulate_args.out.add_to(app, "PREFIX.csv (time series), PREFIX.json, PREFIX.svg (speeds)", true);
    app.add_option("--on-event", simulate_args.on_event,
                   "at the first disengagement or collision: continue (the default: the whole platoon to the end; a car's values after its "
                   "own collision are not physical and its lines end there in the figure) or stop")
        ->capture_default_str();
    app.add_option("--t-end", simulate_args.t_end, "end time [s] (0: the profile's last breakpoint + 30 s)")->capture_default_str();
    app.add_option("--step", simulate_args.step, "largest integration step [s]")->capture_default_str();
    app.add_option("--output-dt", simulate_args.output_dt, "output sampling [s]")->capture_default_str();
    app.add_option("--noise", simulate_args.noise,
                   "measurement noise written to the CSV: Gaussian errors of SD_SPEED [m/s] on every speed and SD_GAP [m] on every gap "
                   "(the dynamics and the JSON summary are exact), e.g. 0.05:0.1")
        ->type_name("SD_SPEED:SD_GAP");
    app.add_option("--seed", simulate_args.seed, "seed of the noise")->capture_default_str();
    simulate_args.format.add_to(app);
    run_flags().add_to(app, true);
}

int run_simulate() {
    if (simulate_args.fleet.empty()) throw BadInput("--fleet is required (e.g. --fleet A_min*7, --fleet mycars.csv or --fleet mycars.csv:Sedan*3)");
    const Format format = simulate_args.format.parse();
    SimOptions o;
    o.step = parse_number("--step", simulate_args.step);
    o.t_end = parse_number("--t-end", simulate_args.t_end);
    o.output_dt = parse_number("--output-dt", simulate_args.output_dt);
    if (simulate_args.on_event == "stop") o.on_event = OnEvent::Stop;
    else if (simulate_args.on_event != "continue") throw BadInput("--on-event = '" + simulate_args.on_event + "': expected stop or continue");
    // each flag's range, named by the flag (SimOptions::validate words them by field)
    if (!(o.step > 0.0 && o.step <= 1.0)) throw BadInput("--step = " + simulate_args.step + ": expected 0 < step <= 1 s");
    if (!(o.t_end >= 0.0)) throw BadInput("--t-end = " + simulate_args.t_end + ": expected >= 0 s (0: the profile's last breakpoint + 30 s)");
    if (!(o.output_dt > 0.0)) throw BadInput("--output-dt = " + simulate_args.output_dt + ": expected > 0 s");
    o.validate();
    const std::string prefix = simulate_args.out.prepare("simulate");
    std::string label;
    const LeadProfile lead = simulate_args.lead.parse(label);
    const std::vector<SimCar> cars = platoon_from(vehicles_argument("--fleet", simulate_args.fleet));
    const SimEstimate size = estimate_simulation(lead, cars, o);
    const std::string what = std::to_string(cars.size()) + " followers over " + rounded(size.t_end, 6) + " s (" +
                             rounded(size.steps, 3) + " steps)";
    check_size("simulate", what, "memory", size.memory_bytes);
    check_size("simulate", what, "output", size.output_bytes);
    check_size("simulate", what, "time", size.car_steps * 2e-6);  // about 2 us per car and step (measured)
    o.progress = progress_printer("simulate", "ms simulated");
    double speed_sd = 0.0, gap_sd = 0.0;
    if (!simulate_args.noise.empty()) {
        const auto colon = simulate_args.noise.find(':');
        if (colon == std::string::npos) throw BadInput("--noise = '" + simulate_args.noise + "': expected SD_SPEED:SD_GAP, e.g. 0.05:0.1");
        speed_sd = parse_number("--noise (speed)", simulate_args.noise.substr(0, colon));
        gap_sd = parse_number("--noise (gap)", simulate_args.noise.substr(colon + 1));
        if (!(speed_sd >= 0 && gap_sd >= 0 && speed_sd <= 10 && gap_sd <= 100))
            throw BadInput("--noise = '" + simulate_args.noise + "': expected standard deviations 0 to 10 m/s and 0 to 100 m");
    }
    const auto seed = static_cast<unsigned long long>(parse_integer("--seed", simulate_args.seed, 0, 4294967295L, "an integer 0..4294967295"));
    SimResult r = simulate_platoon(lead, cars, o);
    const std::string summary = simulation_json(r, label);  // the exact run
    SimResult measured = r;
    add_measurement_noise(measured, speed_sd, gap_sd, seed);
    JsonEnvelope e;
    e.command = "simulate";
    e.inputs = JsonObject()
                   .string("fleet", simulate_args.fleet)
                   .string("lead", label)
                   .string("on_event", simulate_args.on_event)
                   .number("t_end", o.t_end)
                   .number("step", o.step)
                   .number("output_dt", o.output_dt)
                   .number("noise_speed_sd", speed_sd)
                   .number("noise_gap_sd", gap_sd)
                   .integer("seed", static_cast<long long>(seed))
                   .str();
    e.status = to_string(r.status);
    e.message = r.message;
    e.result = summary;
    const std::string csv = simulation_csv(measured);
    write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", simulation_svg(r, label)}});
    print_output(format, e, csv, [&] {
        std::ostringstream s;
        s << "simulated  " << counted(static_cast<long long>(cars.size()), "follower") << " to t = " << rounded(r.t_end, 5) << " s (" << r.steps << " steps)\n";
        std::size_t w = 4;  // the name column fits the longest name
        for (const auto& c : r.cars) w = std::max(w, c.name.size());
        s << "car  " << pad("name", w) << "  min speed [m/s]  speed drop [m/s]  min gap [m]  events\n";
        for (const auto& c : r.cars) {
            char line[160];
            std::snprintf(line, sizeof line, "  %15.3f %17.3f %12.3f  ", c.min_speed, c.speed_drop, c.min_gap);
            char car[16];
            std::snprintf(car, sizeof car, "%3d  ", c.car);
            s << car << pad(c.name, w) << line;
            for (const auto& ev : c.events) s << ev.type << " at " << rounded(ev.time, 4) << " s  ";
            s << "\n";
        }
        s << "wrote      " << prefix << ".csv " << prefix << ".json " << prefix << ".svg\n";
        std::cout << s.str();
    });
    int collisions = 0;
    for (const auto& ev : r.events) collisions += ev.type == "collision";
    if (collisions > 0)  // never silent, whatever the format
        for (const auto& ev : r.events)
            if (ev.type == "collision") {
                std::cerr << "ddemap: simulate: " << counted(collisions, "car") << " collided (the first: car " << ev.car << " at t = " << rounded(ev.time, 4)
                          << " s); in " << prefix << ".svg their lines end at the collision\n";
                break;
            }
    if (r.status != Status::Converged) {
        std::cerr << "ddemap: simulate: UNDECIDED: " << r.message << "\n";
        return exit_not_converged;
    }
    return exit_ok;
}

}  // namespace ddemap::cli
