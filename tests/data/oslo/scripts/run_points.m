% Production driver: per-block first-unstick (front arrival) times for the chosen
% (tau_bar, alpha) points at dt0, dt0/2, dt0/4, dt0/8, using the UNMODIFIED peer
% function integrateSingleSystem.m (via oslo_run.m), plus a cross-check with the
% peer's batched integrateSystem.m (via oslo_run_batch.m + compat_gpu shims) at dt0, dt0/2.
% Invoke:  cd /work/peers/oslo/scripts && nice -n 19 octave-cli -q run_points.m
more off
warning('off', 'Octave:shadowed-function');
here  = fileparts(mfilename('fullpath'));
ddir  = fullfile(here, '..', 'data');
REPO  = 'https://github.com/bokhylle/1dBurridgeKnopoffMatlab';
COMMIT = '7834d80ff99ae9e15a3c2c05df38b80902b85911';
OCTV  = version();
DATE  = datestr(now, 'yyyy-mm-dd HH:MM:SS');
dt0   = 1e-3;
tmax  = 1e4;
% name, tau_bar, alpha, N
P = { 'A_slow',       0.3,  3.0,  50;
      'B_subsonic',   0.1,  0.1, 100;
      'C_supershear', 0.8,  0.1, 100;
      'D_arresting',  0.01, 0.1, 100 };
if exist('ONLY', 'var'), P = P(ONLY, :); end
for ip = 1:rows(P)
  name = P{ip,1}; tau = P{ip,2}; alpha = P{ip,3}; N = P{ip,4};
  for k = 0:3
    dt = dt0 / 2^k;
    [ut, info] = oslo_run(alpha, tau, N, dt, tmax, 'all');
    if ~isnan(ut(end)), reason = 'front reached block N';
    elseif info.t_last_frame < tmax - 2, reason = 'all blocks stuck (front arrested)';
    else reason = 'tmax reached'; end
    fn = fullfile(ddir, sprintf('%s_dt%s.tsv', name, strrep(sprintf('%.6g', dt), '.', 'p')));
    fid = fopen(fn, 'w');
    fprintf(fid, '# Oslo 1-D Burridge-Knopoff peer run: point %s  tau_bar=%g  alpha_bar=%g  N=%d  dt=%.10g\n', name, tau, alpha, N, dt);
    fprintf(fid, '# repository: %s  commit: %s\n', REPO, COMMIT);
    fprintf(fid, '# GNU Octave %s ; run date %s ; wall time %.1f s ; termination: %s\n', OCTV, DATE, info.wall, reason);
    fprintf(fid, '# command: cd /work/peers/oslo/scripts && nice -n 19 octave-cli -q run_points.m  (driver scripts/run_points.m -> scripts/oslo_run.m)\n');
    fprintf(fid, '# peer call: integrateSingleSystem(%g, %g*ones(%d,1), %d, %.10g, %d, %g, ''all'', (%g+2)*ones(%d,1))  [src unmodified]\n', alpha, tau, N, N, dt, round(1/dt), tmax, tau, N);
    fprintf(fid, '# block index is 1-based as in MATLAB (block 1 = driven left edge); t_arrival = peer unstickTime = first step time t at which a_i>=1 for a stuck block; NaN = never unstuck\n');
    fprintf(fid, 'block\tt_arrival\n');
    for i = 1:N, fprintf(fid, '%d\t%.10g\n', i, ut(i)); end
    fclose(fid);
    printf('%s dt=%g wall=%.1f reached=%d %s\n', name, dt, info.wall, sum(~isnan(ut)), reason); fflush(stdout);
  end
  % cross-check with the peer's batched integrateSystem.m (single-precision tau/alpha, v<0 re-stick, no backward unstick)
  for k = 0:1
    dt = dt0 / 2^k;
    [utb, wall] = oslo_run_batch(alpha, tau, N, dt);
    fn = fullfile(ddir, 'batch_crosscheck', sprintf('%s_dt%s.tsv', name, strrep(sprintf('%.6g', dt), '.', 'p')));
    fid = fopen(fn, 'w');
    fprintf(fid, '# CROSS-CHECK with the peer batched code integrateSystem.m (as called by run.m): point %s tau_bar=%g alpha_bar=%g N=%d dt=%.10g\n', name, tau, alpha, N, dt);
    fprintf(fid, '# repository: %s  commit: %s ; GNU Octave %s ; run date %s ; wall %.1f s\n', REPO, COMMIT, OCTV, DATE, wall);
    fprintf(fid, '# command: cd /work/peers/oslo/scripts && nice -n 19 octave-cli -q run_points.m  (-> scripts/oslo_run_batch.m with shims scripts/compat_gpu/*)\n');
    fprintf(fid, '# peer call: integrateSystem(%g, %g, %d, ''unused.mat'', 1, %.10g, @(v,tau) 0.0)  [src unmodified]\n', alpha, tau, N, dt);
    fprintf(fid, '# block index 1-based as in MATLAB; NaN = never unstuck\n');
    fprintf(fid, 'block\tt_arrival\n');
    for i = 1:N, fprintf(fid, '%d\t%.10g\n', i, utb(i)); end
    fclose(fid);
    printf('%s batch dt=%g wall=%.1f reached=%d\n', name, dt, wall, sum(~isnan(utb))); fflush(stdout);
  end
end
