#pragma once
/// \file hopf_output.hpp
/// JSON and CSV of the hopf command (analysis/hopf.hpp): Hopf points with their criticality, and
/// Hopf curves in two parameters. Doubles round-trip exact; a quantity that is not defined (a
/// point that did not converge) is null in JSON and empty in CSV.

#include <string>
#include <vector>

#include "ddemap/analysis/bifurcation/bistability.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/io/csv.hpp"

namespace ddemap {

/// {"parameter", "variables", "hopf": [{"par", "omega", "l1", "criticality", "status",
/// "equilibrium", "dre_dpar", "side", "amplitude_coefficient", "c1", "residual", "message"}],
/// "branch": {"points", "stop", "status"}}. criticality is "undecided" for a point without
/// coefficients (its status says why).
std::string hopf_points_json(const HopfAnalysis& a, const std::vector<std::string>& variables);
/// PAR,omega_rad_per_s,l1,criticality,dre_dpar,side,VAR...(equilibrium),amp_VAR...,residual,status
/// (PAR and VAR the names with their units from `units`; amp_VAR in VAR's unit per square root of
/// PAR's).
std::string hopf_points_csv(const HopfAnalysis& a, const std::vector<std::string>& variables, const ColumnUnits& units = {});

/// {"parameter", "parameter2", "hopf": [the starting points as above], "curves": [{"start",
/// "status", "message", "stop": [backward, forward], "points": [{"par", "par2", "omega", "l1",
/// "criticality", "dre_dpar"}], "generalised_hopf": [{"par", "par2", "omega", "l1", "l2", "status",
/// "normal_form": {"c1", "c2", "l2"}}], "double_hopf": [{"par", "par2", "omega1", "omega2", "residual",
/// "other_curve", "resonant_1_1", "status", "message", "normal_form": {"g2100", "g1011", "g1110",
/// "g0021", "theta", "delta"}}], "zero_hopf": [{..., "normal_form"}], "bogdanov_takens": [{"par",
/// "par2", "end", "residual", "status", "message", "normal_form": {"a", "b"}}]}]} (a normal form
/// null where it was not formed, with "normal_form_message" saying why at a located point)
std::string hopf_curves_json(const HopfCurves& c, const std::string& parameter2, const std::vector<std::string>& variables);
/// curve,kind,PAR,PAR2,omega_rad_per_s,l1,criticality,status (kind: point, generalised_hopf,
/// double_hopf, zero_hopf or bogdanov_takens (omega 0); PAR and PAR2 the parameters' names with their units from `units`)
std::string hopf_curves_csv(const HopfCurves& c, const std::string& parameter2, const ColumnUnits& units = {});

/// The criticality word of a point: to_string(criticality), or "undecided" when its
/// coefficients did not converge.
std::string criticality_word(const HopfCoefficients& c);

/// The bistability chart (analysis/bifurcation/bistability.hpp): {"parameter", "parameter2",
/// "box": [from, to, from2, to2], "hopf": hopf_curves_json, "fold_curves": orbit_fold_curves_json,
/// "cells": [{"par", "par2", "equilibrium_stable", "stable_orbit", "bistable", "status",
/// "message", "intervals": [[par2, lo, hi], ...]}], "slices", "rounds"}.
std::string bistability_json(const BistabilityChart& c, const std::vector<std::string>& variables);
/// The curves, one row per point: curve,kind,PAR,PAR2 (names with units) with kind hopf_supercritical,
/// hopf_subcritical, hopf (L1 not decided), generalised_hopf or fold_of_orbits (curve numbered
/// within its kind: Hopf curves, then fold curves).
std::string bistability_csv(const BistabilityChart& c, const ColumnUnits& units = {});

}  // namespace ddemap
