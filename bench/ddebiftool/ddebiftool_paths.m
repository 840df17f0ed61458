function ok = ddebiftool_paths(extra)
% Adds DDE-BIFTOOL's folders (from the environment variable DDEBIFTOOL_DIR) and `extra` (a cell
% array of folders below it, e.g. {'demos/minimal_demo'}) to the path, and switches warnings
% off. False (with a message) when DDEBIFTOOL_DIR is not set: the caller then skips its run.
ddir = getenv('DDEBIFTOOL_DIR');
ok = ~isempty(ddir);
if ~ok
    disp('DDEBIFTOOL_DIR is not set: skipped');
    return;
end
if nargin < 1, extra = {}; end
addpath(fullfile(ddir, 'ddebiftool'), fullfile(ddir, 'ddebiftool_extra_psol'), ...
        fullfile(ddir, 'ddebiftool_extra_nmfm'), fullfile(ddir, 'ddebiftool_utilities'));
for k = 1:numel(extra), addpath(fullfile(ddir, extra{k})); end
warning('off', 'all');
end
