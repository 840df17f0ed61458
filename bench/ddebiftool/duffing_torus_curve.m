% The curve of torus (Neimark-Sacker) bifurcations in (tau, b) of DDE-BIFTOOL's minimal demo
% (Duffing oscillator with delayed feedback, examples/duffing.json), continued by DDE-BIFTOOL's
% SetupTorusBifurcation from the torus on the branch of orbits born at the Hopf point near
% tau = 7.3195 (b = 0.6), degree 4 on 30 uniform intervals (no mesh adaptation), as
% `ddemap orbits --system examples/duffing.json --par tau --from 0 --to 20 --hopf 1 --points 12
% --intervals 30 --par2 b --from2 0.3 --to2 0.9` does. Prints one line per point of the torus
% curve ("ddebiftool torus_curve tau <tau> b <b> period <T>") and the CPU time of the continuation.
%
% Run: DDEBIFTOOL_DIR=/path/to/DDE-Biftool octave --no-gui --quiet duffing_torus_curve.m
% Under Octave (7.3) DDE-BIFTOOL's ddebiftool/dde_sys_cond_collect.m fails to concatenate an empty
% column with a row ("cat: dimension mismatch") when the torus extension adds its conditions; the
% two lines r=[ru,res{:}]'; J=[Ju,Jac{:}]'; then need ru(:)' and Ju(:)' in place of ru and Ju.
addpath(fileparts(mfilename('fullpath')));  % ddebiftool_paths.m, duffing_orbit_branch.m
if ~ddebiftool_paths({fullfile('demos', 'minimal_demo')}), exit(0); end
format long
[funcs, per, indp, ich] = duffing_orbit_branch(30);
if isempty(ich), exit(1); end
t0 = cputime;
[trfuncs, trbr, suc] = SetupTorusBifurcation(funcs, per, ich, 'contpar', [indp.tau, indp.b], 'dir', indp.b, 'step', -0.01);
if ~suc
    disp('initialisation of the torus curve failed');
    exit(1);
end
trbr.method.continuation.plot = 0;
trbr.parameter.max_bound = [indp.b, 0.9];
trbr.parameter.min_bound = [indp.b, 0.3];
trbr.parameter.max_step = [0, 0.1; indp.b, 0.05];
trbr.method.continuation.adapt_mesh_before_correct = 0;
trbr.method.continuation.adapt_mesh_after_correct = 0;
n = str2double(getenv('POINTS'));
if isnan(n), n = 20; end
trbr = br_contn(trfuncs, trbr, n);
trbr = br_rvers(trbr);
trbr = br_contn(trfuncs, trbr, n);
t1 = cputime;
for k = 1:numel(trbr.point)
    p = trbr.point(k);
    fprintf('ddebiftool torus_curve tau %.12f b %.12f period %.12f\n', p.parameter(indp.tau), p.parameter(indp.b), p.period);
end
fprintf('ddebiftool torus_curve points %d cpu %.3f s\n', numel(trbr.point), t1 - t0);
