/* Hermite interpolation (hermite.h) in Newton form: confluent divided differences, each node
 * taken twice, so that building costs O(n k^2) and an evaluation O(n k). */
#include "solver/hermite.h"

#include <stdlib.h>

#include "capacity.h"

int bk_hermite_reserve(bk_hermite *h, size_t n)
{
    h->m = 0;
    if (!bk_capacity_fits(n, h->capacity) || !h->c) {
        double *c = realloc(h->c, 2 * BK_HERMITE_MAX_NODES * (n ? n : 1) * sizeof *c);
        if (!c)
            return -1;
        h->c = c;
        h->capacity = n;
    }
    h->n = n;
    return 0;
}

void bk_hermite_free(bk_hermite *h)
{
    free(h->c);
    h->c = NULL;
    h->n = h->m = h->capacity = 0;
}

void bk_hermite_build(bk_hermite *h, size_t k, const double *t, const double *const *y,
                      const double *const *f)
{
    size_t m = 2 * k;
    h->m = m;
    for (size_t i = 0; i < m; ++i)
        h->z[i] = t[i / 2];
    for (size_t comp = 0; comp < h->n; ++comp) {
        double d[2 * BK_HERMITE_MAX_NODES] = {0};
        for (size_t i = 0; i < m; ++i)
            d[i] = y[i / 2][comp];
        double *c = h->c + comp * m;
        c[0] = d[0];
        for (size_t j = 1; j < m; ++j) {
            for (size_t i = m - 1; i >= j; --i)
                /* Equal abscissae only in the first column: the node's derivative. */
                d[i] = j == 1 && i % 2 == 1 ? f[i / 2][comp]
                                            : (d[i] - d[i - 1]) / (h->z[i] - h->z[i - j]);
            c[j] = d[j];
        }
    }
}

void bk_hermite_eval(const bk_hermite *h, double t, double *out, double *tail)
{
    size_t m = h->m;
    double w[2 * BK_HERMITE_MAX_NODES];
    w[0] = 1.0;
    for (size_t j = 1; j < m; ++j)
        w[j] = w[j - 1] * (t - h->z[j - 1]);
    for (size_t comp = 0; comp < h->n; ++comp) {
        const double *c = h->c + comp * m;
        double p = 0.0;
        for (size_t j = 0; j + 2 < m; ++j)
            p += c[j] * w[j];
        double last = c[m - 2] * w[m - 2] + c[m - 1] * w[m - 1];
        out[comp] = p + last;
        if (tail)
            tail[comp] = last;
    }
}
