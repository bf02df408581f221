% Post-processing of the per-(point,dt) TSVs written by run_points.m:
% front speed fits, O(dt) convergence, Richardson extrapolation, batch-code cross-check.
% Invoke:  cd /work/peers/oslo/scripts && nice -n 19 octave-cli -q analyze.m
more off
here = fileparts(mfilename('fullpath'));
ddir = fullfile(here, '..', 'data');
REPO = 'https://github.com/bokhylle/1dBurridgeKnopoffMatlab';
COMMIT = '7834d80ff99ae9e15a3c2c05df38b80902b85911';
OCTV = version(); DATE = datestr(now, 'yyyy-mm-dd HH:MM:SS');
dt0 = 1e-3;
P = { 'A_slow',       0.3,  3.0,  50, 'slow';
      'B_subsonic',   0.1,  0.1, 100, 'sub-Rayleigh (sub-sonic, v_f<1)';
      'C_supershear', 0.8,  0.1, 100, 'supershear (v_f>1)';
      'D_arresting',  0.01, 0.1, 100, 'arresting front (all blocks re-stick before reaching block N)' };
fname = @(name, dt, sub) fullfile(ddir, sub, sprintf('%s_dt%s.tsv', name, strrep(sprintf('%.6g', dt), '.', 'p')));
function t = readut(fn)
  fid = fopen(fn, 'r'); t = [];
  while true
    l = fgetl(fid); if ~ischar(l), break; end
    if isempty(l) || l(1) == '#' || strncmp(l, 'block', 5), continue; end
    c = sscanf(strrep(l, 'NaN', 'NaN'), '%f'); t(c(1), 1) = c(2);
  end
  fclose(fid);
end
function [s, s2] = speedfit(t)
  idx = find(~isnan(t)); s = NaN; s2 = NaN;
  if numel(idx) >= 3, p = polyfit(idx, t(idx), 1); s = 1/p(1); end
  h = idx(idx > max(idx)/2);
  if numel(h) >= 3, p = polyfit(h, t(h), 1); s2 = 1/p(1); end
end
hdr = sprintf(['# repository: %s  commit: %s\n# GNU Octave %s ; analysis date %s\n' ...
               '# command: cd /work/peers/oslo/scripts && nice -n 19 octave-cli -q analyze.m (reads data/<point>_dt*.tsv written by run_points.m)\n'], REPO, COMMIT, OCTV, DATE);
fs = fopen(fullfile(ddir, 'summary.tsv'), 'w');
fprintf(fs, '%s', hdr);
fprintf(fs, '# front_speed = 1/slope of least-squares fit t_arrival = a + b*block over ALL reached blocks (blocks/unit time; sound speed = 1)\n');
fprintf(fs, '# front_speed_2nd_half = same fit restricted to reached blocks with index > (last reached)/2\n');
fprintf(fs, '# max_change_vs_half_dt = max over blocks reached in both runs of |t_i(dt) - t_i(dt/2)| (NaN for the finest dt)\n');
fprintf(fs, '# max_diff_vs_batch = max_i |t_i(integrateSingleSystem) - t_i(integrateSystem batch code)| at the same dt (NaN if not run)\n');
fprintf(fs, 'point\ttau\talpha\tN\tdt\tfront_speed\tn_blocks_reached\tmax_change_vs_half_dt\tfront_speed_2nd_half\tmax_diff_vs_batch\tclassification\n');
fc = fopen(fullfile(ddir, 'convergence.tsv'), 'w');
fprintf(fc, '%s', hdr);
fprintf(fc, '# max_abs/mean_abs over blocks reached in both runs; observed_order = log2(max_abs(previous pair)/max_abs(this pair))\n');
fprintf(fc, '# rich_vs_finest: max_i |R_i - t_i(dt0/8)| where R = 2 t(dt/2) - t(dt) for the pair; rich_pair_spread: max_i |R(dt0,dt0/2) - R(dt0/4,dt0/8)|\n');
fprintf(fc, '# mean_signed_diff = mean_i (t_i(dt_coarse) - t_i(dt_fine)); detection is rounded UP to the step grid, so a pure quantization bias would give about +dt_coarse/4\n');
fprintf(fc, 'point\tdt_coarse\tdt_fine\tmax_abs_diff\tmean_abs_diff\tblock_of_max\tobserved_order\tmax_abs_rich_minus_finest\tn_reached_coarse\tn_reached_fine\tmean_signed_diff\tmax_abs_diff_over_dt_coarse\n');
for ip = 1:rows(P)
  name = P{ip,1}; tau = P{ip,2}; alpha = P{ip,3}; N = P{ip,4};
  T = NaN(N, 4); TB = NaN(N, 2);
  for k = 0:3, T(:, k+1) = readut(fname(name, dt0/2^k, '')); end
  for k = 0:1
    fb = fname(name, dt0/2^k, 'batch_crosscheck');
    if exist(fb, 'file'), TB(:, k+1) = readut(fb); end
  end
  prev = NaN;
  for k = 0:3
    dt = dt0/2^k; [s, s2] = speedfit(T(:, k+1)); nr = sum(~isnan(T(:, k+1)));
    mc = NaN;
    if k < 3
      d = abs(T(:, k+1) - T(:, k+2)); ok = ~isnan(d);
      mc = max(d(ok));
      [~, im] = max(d .* ok); ordr = log2(prev / mc);
      R = 2*T(:, k+2) - T(:, k+1); rf = max(abs(R(ok) - T(ok, 4)));
      sd = T(:, k+1) - T(:, k+2);
      fprintf(fc, '%s\t%.10g\t%.10g\t%.6g\t%.6g\t%d\t%.3g\t%.6g\t%d\t%d\t%.6g\t%.4g\n', name, dt, dt/2, mc, mean(d(ok)), im, ordr, rf, nr, sum(~isnan(T(:, k+2))), mean(sd(ok)), mc/dt);
      prev = mc;
    end
    mb = NaN;
    if k < 2 && any(~isnan(TB(:, k+1)))
      db = abs(T(:, k+1) - TB(:, k+1)); mb = max(db(~isnan(db)));
      if any(isnan(T(:, k+1)) ~= isnan(TB(:, k+1))), mb = Inf; end  % reached sets differ
    end
    fprintf(fs, '%s\t%g\t%g\t%d\t%.10g\t%.6g\t%d\t%.6g\t%.6g\t%.6g\t%s\n', name, tau, alpha, N, dt, s, nr, mc, s2, mb, P{ip,5});
  end
  % per-block Richardson table
  fr = fopen(fullfile(ddir, sprintf('%s_richardson.tsv', name)), 'w');
  fprintf(fr, '%s', hdr);
  fprintf(fr, '# point %s tau_bar=%g alpha_bar=%g N=%d ; block index 1-based as in MATLAB; NaN = never unstuck\n', name, tau, alpha, N);
  fprintf(fr, '# t_dtK = arrival at dt = 1e-3/K ; rich_1_2 = 2 t_dt2 - t_dt1 ; rich_4_8 = 2 t_dt8 - t_dt4 (best dt->0 estimate)\n');
  fprintf(fr, 'block\tt_dt1\tt_dt2\tt_dt4\tt_dt8\trich_1_2\trich_2_4\trich_4_8\n');
  for i = 1:N
    fprintf(fr, '%d\t%.10g\t%.10g\t%.10g\t%.10g\t%.10g\t%.10g\t%.10g\n', i, T(i,:), 2*T(i,2)-T(i,1), 2*T(i,3)-T(i,2), 2*T(i,4)-T(i,3));
  end
  fclose(fr);
  R12 = 2*T(:,2)-T(:,1); R48 = 2*T(:,4)-T(:,3); ok = ~isnan(R12) & ~isnan(R48);
  printf('%s: rich spread max|R12-R48| = %.4g\n', name, max(abs(R12(ok)-R48(ok))));
end
fclose(fs); fclose(fc);
