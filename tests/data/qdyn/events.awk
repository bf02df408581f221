# Extract events from a QDYN output_ot_0 (columns: 1 t, 2 pot, 3 pot_rate, 4 V, 5 theta, 6 tau, 7 dtau_dt, 8 slip, 9 sigma)
# Event = V crossing vth upward (onset) then downward (end). Each crossing is located by linear interpolation
# in log V between the two output samples that bracket it; slip at the crossing is interpolated linearly in
# time at that instant (same fraction). peak_v = max sample V between onset and end.
# usage: awk -v vth=0.01 -f events.awk output_ot_0   -> lines: event onset end peak_v slip_onset slip_end slip
BEGIN { if (vth == "") vth = 0.01; lvth = log(vth); n = 0; inev = 0; ne = 0; OFMT = "%.17g" }
/^#/ { next }
{
  t = $1 + 0; v = $4 + 0; s = $8 + 0
  if (n > 0) {
    if (!inev && vp < vth && v >= vth) {
      f = (lvth - log(vp)) / (log(v) - log(vp)); ton = tp + f * (t - tp); son = sp + f * (s - sp)
      inev = 1; pk = v; ne++
    } else if (inev && v > pk) pk = v
    if (inev && vp >= vth && v < vth) {
      f = (lvth - log(vp)) / (log(v) - log(vp)); toff = tp + f * (t - tp); soff = sp + f * (s - sp)
      printf "%d\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\n", ne, ton, toff, pk, son, soff, soff - son
      inev = 0
    }
  }
  tp = t; vp = v; sp = s; n++
}
END { if (inev) printf "%d\t%.17g\tNA\t%.17g\t%.17g\tNA\tNA\n", ne, ton, pk, son }
