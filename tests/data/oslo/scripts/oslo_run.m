function [ut, info] = oslo_run(alpha, tau, N, dt, tmax, saveMode)
% Thin driver around the UNMODIFIED peer function integrateSingleSystem.m
% (bokhylle/1dBurridgeKnopoffMatlab). Homogeneous tau_bar on all blocks,
% tau_bar_minus = tau_bar + 2 exactly as in the peer's runSingleRuns.m.
% Returns per-block first-unstick times (NaN = never unstuck) and run info.
if nargin < 6, saveMode = 'all'; end
here = fileparts(mfilename('fullpath'));
warning('off', 'Octave:shadowed-function');
addpath(fullfile(here, '..', 'src'));
tauv = tau * ones(N,1);
taum = tauv + 2;
outputFreq = max(1, round(1/dt));   % one stored frame per unit time (needs >=1 frame)
tic;
[x_all, v_all, a_all, stuck_all, ut, t_all] = integrateSingleSystem(alpha, tauv, N, dt, outputFreq, tmax, saveMode, taum);
info.wall = toc;
info.t_last_frame = t_all(end);
if strcmp(saveMode,'all') || strcmp(saveMode,'arresting')
  info.x_final = x_all(:,end); info.v_final = v_all(:,end); info.stuck_final = stuck_all(:,end);
end
end
