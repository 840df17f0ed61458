function [funcs, per, indp, ich] = duffing_orbit_branch(L)
% The branch of periodic orbits of DDE-BIFTOOL's minimal demo (examples/duffing.json) born at
% the Hopf point near tau = 7.3195 (b = 0.6), degree 4 on L uniform intervals, no mesh adaptation,
% 40 orbits continued in tau, with their stability; ich: the orbit after which the number of
% unstable multipliers changes (the torus bifurcation), empty when it does not.
indp = struct('tau', 1, 'a', 2, 'b', 3, 'd', 4);
funcs = set_symfuncs(@sym_minimal_demo, 'sys_tau', @() indp.tau);
par = [0, 0.5, 0.6, 0.05];
br_args = {'max_bound', [indp.tau, 20], 'min_bound', [indp.tau, 0], 'max_step', [0, 2; indp.tau, 0.2]};
[eqs, ~] = SetupStst(funcs, 'x', [0; 0], 'parameter', par, 'contpar', indp.tau, br_args{:}, 'minimal_real_part', -1);
eqs.method.continuation.plot = 0;
eqs = br_contn(funcs, eqs, 60);
[eqs, ~, ind_hopf] = LocateSpecialPoints(funcs, eqs);
hopf_taus = arrayfun(@(i) eqs.point(i).parameter(indp.tau), ind_hopf);
[~, ih] = min(abs(hopf_taus - 7.3195));
fprintf('Hopf point used: tau = %.10f\n', eqs.point(ind_hopf(ih)).parameter(indp.tau));
[per, suc] = SetupPsol(funcs, eqs, ind_hopf(ih), 'intervals', L, 'degree', 4, 'max_bound', [indp.tau, 20], ...
                       'min_bound', [indp.tau, 0], 'max_step', [0, 0.1; indp.tau, 0.02], 'print_residual_info', 0);
ich = [];
if ~suc
    fprintf('L = %d: the first orbit did not converge\n', L);
    return;
end
per.method.continuation.adapt_mesh_before_correct = 0;
per.method.continuation.adapt_mesh_after_correct = 0;
per.method.continuation.plot = 0;
per = br_contn(funcs, per, 40);
[nunst, ~, ~, per.point] = GetStability(per, 'exclude_trivial', true, 'funcs', funcs);
taus = arrayfun(@(p) p.parameter(indp.tau), per.point);
ich = find(diff(nunst(:)) ~= 0 & taus(2:end)' < 7.2, 1);
if isempty(ich)
    fprintf('L = %d: no change of stability on %d orbits (tau %.4f..%.4f)\n', L, numel(taus), min(taus), max(taus));
else
    fprintf('L = %d: unstable multipliers %d -> %d between tau = %.8f and %.8f\n', L, nunst(ich), nunst(ich + 1), taus(ich), taus(ich + 1));
end
end
