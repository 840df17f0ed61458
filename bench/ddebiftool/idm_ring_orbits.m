% The 10-car IDM ring's branch of periodic orbits with DDE-BIFTOOL, for the side-by-side timing of
% bench/ddebiftool/compare.sh against `ddemap orbits` / bench_orbits --model idm.
%
% The same system as ddemap's IdmRing (include/ddemap/traffic/idm_ring.hpp): 10 cars, the last
% gap eliminated (19 states), parameters a = 1, b = 1.5, v0 = 33.3, delta = 4, th = 1.2, eta = 2,
% tau = 0.6, the gap free; the same mesh (degree 4, 40 intervals, no mesh adaptation), 100 orbits
% from the first Hopf point of the uniform flow in the gap, Floquet multipliers of every orbit.
% DDE-BIFTOOL's own step control and its default finite-difference derivatives.
%
% Run: DDEBIFTOOL_DIR=/path/to/DDE-Biftool octave --no-gui --quiet idm_ring_orbits.m
% Prints one line "ddebiftool orbits <n> cpu_branch <s> cpu_floquet <s> wall <s> ..." at the end.
% Optional: ORBITS=<n> (default 100); DDEBIFTOOL_POINTS=<file.csv> writes every orbit (gap, period,
% number of unstable nontrivial multipliers, |mu_trivial - 1|, the 6 largest nontrivial |mu|) for
% the point-by-point stability comparison with `ddemap orbits` (not timed).
addpath(fileparts(mfilename('fullpath')));  % ddebiftool_paths.m
if ~ddebiftool_paths(), exit(0); end
npoints = 100;
s = getenv('ORBITS');
if ~isempty(s), npoints = str2double(s); end
N = 10;
names = {'a', 'b', 'v0', 'delta', 'th', 'eta', 'tau', 'gap'};
ind = struct();
for k = 1:numel(names), ind.(names{k}) = k; end
par0 = [1, 1.5, 33.3, 4, 1.2, 2, 0.6, 6];

function out = idm_rhs(xx, p, N)
    a = p(1); b = p(2); v0 = p(3); delta = p(4); th = p(5); eta = p(6); gap = p(8);
    x = xx(:, 1); xd = xx(:, 2);
    v = x(N:2 * N - 1); sd = xd(1:N - 1); vd = xd(N:2 * N - 1);
    out = zeros(2 * N - 1, 1);
    out(1:N - 1) = v(2:N) - v(1:N - 1);
    gaps = [sd; N * gap - sum(sd)];
    lead = vd([2:N, 1]);
    desired = eta + th * v + v .* (v - lead) / (2 * sqrt(a * b));
    term = zeros(N, 1);
    pos = v > 0;
    term(pos) = (v(pos) / v0) .^ delta;
    out(N:2 * N - 1) = a * (1 - term - (desired ./ gaps) .^ 2);
end

funcs = set_funcs('sys_rhs', @(xx, p) idm_rhs(xx, p, N), 'sys_tau', @() ind.tau);
% the uniform flow at gap 6: s*(v) = (eta + th v) / sqrt(1 - (v / v0)^delta) = gap
vstar = fzero(@(v) (par0(6) + par0(5) * v) / sqrt(1 - (v / par0(3))^par0(4)) - par0(8), [0, par0(3) * (1 - 1e-12)]);
x0 = [par0(8) * ones(N - 1, 1); vstar * ones(N, 1)];
t0 = tic;
stst = SetupStst(funcs, 'x', x0, 'parameter', par0, 'contpar', ind.gap, 'step', 0.05, ...
                 'max_step', [ind.gap, 0.2], 'min_bound', [ind.gap, 6], 'max_bound', [ind.gap, 9]);
stst.method.continuation.plot = 0;
stst = br_contn(funcs, stst, 60);
[nunst, ~, ~, stst.point] = GetStability(stst, 'funcs', funcs);
ih = find(diff(nunst) ~= 0, 1);
if isempty(ih)
    disp('no Hopf point on the uniform flow branch in gap from 6 to 9');
    exit(1);
end
fprintf('uniform flow: stability changes between gap %.6f and %.6f (%.1f s)\n', stst.point(ih).parameter(ind.gap), ...
        stst.point(ih + 1).parameter(ind.gap), toc(t0));
[per, suc] = SetupPsol(funcs, stst, ih + 1, 'degree', 4, 'intervals', 40, 'max_bound', [ind.gap, 40], ...
                       'min_bound', [ind.gap, 6], 'print_residual_info', 0);
if ~suc
    disp('DDE-BIFTOOL: the first periodic orbit from the Hopf point did not converge');
    exit(1);
end
per.method.continuation.adapt_mesh_before_correct = 0;
per.method.continuation.adapt_mesh_after_correct = 0;
per.method.continuation.plot = 0;
c0 = cputime; w0 = tic;
per = br_contn(funcs, per, npoints - numel(per.point));
cpu_branch = cputime - c0;
c1 = cputime;
[nunst_per, dom, triv, per.point] = GetStability(per, 'exclude_trivial', true, 'funcs', funcs);
cpu_floquet = cputime - c1;
wall = toc(w0);
gaps = arrayfun(@(p) p.parameter(ind.gap), per.point);
periods = arrayfun(@(p) p.period, per.point);
fprintf('ddebiftool orbits %d cpu_branch %.2f cpu_floquet %.2f cpu %.2f wall %.2f gap %.8f..%.8f period %.8f..%.8f max_trivial %.1e\n', ...
        numel(per.point), cpu_branch, cpu_floquet, cpu_branch + cpu_floquet, wall, min(gaps), max(gaps), min(periods), ...
        max(periods), max(abs(triv)));
pfile = getenv('DDEBIFTOOL_POINTS');
if ~isempty(pfile)
    fid = fopen(pfile, 'w');
    fprintf(fid, 'gap,period,nunst,trivial_dist,absmu1,absmu2,absmu3,absmu4,absmu5,absmu6\n');
    for i = 1:numel(per.point)
        mu = per.point(i).stability.mu(:);
        [~, it] = min(abs(mu - 1));
        mu(it) = [];
        am = sort(abs(mu), 'descend');
        am = [am; zeros(6, 1)];
        fprintf(fid, '%.12g,%.12g,%d,%.3e,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n', gaps(i), periods(i), nunst_per(i), ...
                abs(triv(i)), am(1:6));
    end
    fclose(fid);
end
