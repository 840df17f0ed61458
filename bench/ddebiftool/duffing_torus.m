% The torus (Neimark-Sacker) bifurcation on the branch of periodic orbits of DDE-BIFTOOL's minimal
% demo (Duffing oscillator with delayed feedback, Yanchuk and Perlikowski, PRE 79, 046221, 2009):
%     x1' = x2,  x2' = -d x2 - a x1 - x1^3 - b (x1 - x1(t - tau)),  a = 0.5, b = 0.6, d = 0.05,
% the orbits born at the Hopf point near tau = 7.3195 (omega = 1.30248), continued in tau. This is
% the reference of tests/analysis/test_orbit_torus.cpp (ddemap: examples/duffing.json,
% `ddemap orbits --system examples/duffing.json --par tau --from 0 --to 20 --hopf 1`).
%
% For each mesh (degree 4, L = 20, 30, 40, 60, 80 intervals, uniform, no mesh adaptation; Gauss-Legendre
% collocation as in ddemap) the branch is continued until the number of unstable Floquet
% multipliers changes, and the torus point is then located on DDE-BIFTOOL's own orbits
% (|mu| - 1 of the crossing complex pair brought to zero by regula falsi in tau, every orbit
% corrected by p_correc and its multipliers computed by p_stabil), using the demo's symbolic
% right-hand side and derivatives (demos/minimal_demo/sym_minimal_demo.m).
%
% Run: DDEBIFTOOL_DIR=/path/to/DDE-Biftool octave --no-gui --quiet duffing_torus.m
% Prints one line "ddebiftool torus L <L> tau <tau> period <T> omega <rotation/pi> ..." per mesh.
addpath(fileparts(mfilename('fullpath')));  % ddebiftool_paths.m, duffing_orbit_branch.m
if ~ddebiftool_paths({fullfile('demos', 'minimal_demo')}), exit(0); end
format long
function [g, mu] = crossing_g(funcs, method, orbit)
    % |mu| - 1 of the complex multiplier (|Im mu| > 1e-6) nearest the unit circle
    st = p_stabil(funcs, orbit, method.stability);
    mu = st.mu;
    c = mu(abs(imag(mu)) > 1e-6);
    [~, k] = min(abs(abs(c) - 1));
    g = abs(c(k)) - 1;
end
meshes = [20, 30, 40, 60, 80];
s = getenv('MESHES');
if ~isempty(s), meshes = str2num(s); end
for L = meshes
    [funcs, per, indp, ich] = duffing_orbit_branch(L);
    if isempty(ich), continue; end
    % locate |mu| = 1 of the complex pair that crosses by Illinois regula falsi in tau, every trial
    % orbit corrected at fixed tau (period free, DDE-BIFTOOL's phase condition) from the nearer
    % branch orbit and its multipliers computed by p_stabil
    pa = per.point(ich); pb = per.point(ich + 1);
    [ga, ~] = crossing_g(funcs, per.method, pa);
    [gb, ~] = crossing_g(funcs, per.method, pb);
    ta = pa.parameter(indp.tau); tb = pb.parameter(indp.tau);
    side = 0; best = pb; mu = [];
    for it = 1:60
        t = (ta * gb - tb * ga) / (gb - ga);
        if abs(t - ta) < abs(t - tb), guess = pa; else, guess = pb; end
        guess.parameter(indp.tau) = t;
        [orbit, ok] = p_correc(funcs, guess, [], [], per.method.point);
        if ~ok, fprintf('L = %d: an orbit at tau = %.10f did not converge\n', L, t); break; end
        [g, mu] = crossing_g(funcs, per.method, orbit);
        best = orbit;
        if abs(g) < 1e-11 || abs(tb - ta) < 1e-13, break; end
        if sign(g) == sign(ga)
            ta = t; ga = g; pa = orbit;
            if side == -1, gb = gb / 2; end
            side = -1;
        else
            tb = t; gb = g; pb = orbit;
            if side == 1, ga = ga / 2; end
            side = 1;
        end
    end
    [g, k] = min(abs(abs(mu) - 1) + (abs(imag(mu)) < 1e-6));
    fprintf('ddebiftool torus L %d tau %.12f period %.12f mu %.10f %+.10fi absmu-1 %.2e trivial %.2e its %d\n', ...
            L, best.parameter(indp.tau), best.period, real(mu(k)), abs(imag(mu(k))), abs(mu(k)) - 1, ...
            min(abs(mu - 1)), it);
end

