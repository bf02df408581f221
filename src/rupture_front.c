/* The front speeds of a rupture (bksim/rupture.h: bk_rupture_front_speeds): least-squares
 * fits of arrival time against distance from the epicentre, one per side. */
#include <math.h>

#include "bksim/rupture.h"

/* Signed distance from a to b along a direction of len lines (the shorter way on a ring). */
static double line_distance(long a, long c, size_t len, int ring)
{
    long d = c - a;
    if (ring) {
        long n = (long)len;
        d = ((d % n) + n) % n;
        if (d > n / 2)
            d -= n;
    }
    return (double)d;
}

/* The least-squares slope's reciprocal of t against d over n points (see rupture.h). */
static double fit_speed(double sd, double st, double sdd, double sdt, double count)
{
    if (count < 3.0)
        return NAN;
    double var = sdd - sd * sd / count, cov = sdt - sd * st / count;
    if (!(var > 0.0))
        return NAN;
    double slope = cov / var;
    return slope == 0.0 ? INFINITY : slope > 0.0 ? 1.0 / slope : NAN;
}

void bk_rupture_front_speeds(const bk_rupture_block *blocks, size_t n, int32_t epicentre,
                             size_t rows, size_t cols, int ring_rows, int ring_cols, double *left,
                             double *right)
{
    /* Sums of d, t, d^2, d t and counts, per side; times relative to the epicentre's. */
    double s[2][5] = {{0}};
    double t0 = NAN;
    for (size_t k = 0; k < n; ++k)
        if (blocks[k].block == epicentre)
            t0 = blocks[k].t_onset;
    long e_row = epicentre / (long)cols, e_col = epicentre % (long)cols;
    for (size_t k = 0; k < n; ++k) {
        long row = blocks[k].block / (long)cols, col = blocks[k].block % (long)cols;
        double dc = line_distance(e_col, col, cols, ring_cols);
        double dr = rows > 1 ? line_distance(e_row, row, rows, ring_rows) : 0.0;
        double d = rows > 1 ? sqrt(dr * dr + dc * dc) : fabs(dc);
        double t = blocks[k].t_onset - t0;
        /* Sides by column; in the epicentre's column by row, so a one-column lattice reads
         * as a chain. */
        double along = dc != 0.0 ? dc : dr;
        for (int side = 0; side < 2; ++side) {
            if (side == 0 ? along > 0.0 : along < 0.0)
                continue;
            s[side][0] += d;
            s[side][1] += t;
            s[side][2] += d * d;
            s[side][3] += d * t;
            s[side][4] += 1.0;
        }
    }
    *left = fit_speed(s[0][0], s[0][1], s[0][2], s[0][3], s[0][4]);
    *right = fit_speed(s[1][0], s[1][1], s[1][2], s[1][3], s[1][4]);
}

