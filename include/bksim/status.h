/* Status codes and the error record every bksim function fills on failure.
 *
 * Convention: 0 is success, positive values are informative (a root was found, the stop
 * time was reached), negative values are failures.  A failing function writes a message
 * into the caller's bk_error and returns the same negative code it stored there. */
#ifndef BKSIM_STATUS_H
#define BKSIM_STATUS_H

#include <stddef.h>

/* X(name, value, description): one list makes both the enum and bk_strerror(). */
#define BK_STATUS_LIST(X)                                                              \
    X(BK_INCOMPLETE, 1, "output of a run that did not finish")                         \
    X(BK_OK, 0, "success")                                                             \
    X(BK_ERR_INVALID, -1, "invalid argument")                                          \
    X(BK_ERR_CONFIG, -2, "invalid configuration")                                      \
    X(BK_ERR_IO, -3, "input/output error")                                             \
    X(BK_ERR_NOMEM, -4, "out of memory")                                               \
    X(BK_ERR_SOLVER, -5, "integrator failure")                                         \
    X(BK_ERR_ZENO, -6, "transitions pile up at one instant (chattering)")              \
    X(BK_ERR_MAX_STEPS, -7, "too many solver steps between outputs")                   \
    X(BK_ERR_HDF5, -8, "HDF5 error")                                                   \
    X(BK_ERR_NUMERIC, -9, "non-finite value in the solution")                          \
    X(BK_ERR_SINK, -10, "output sink failed")                                          \
    X(BK_ERR_INTERRUPTED, -11, "run interrupted")                                     \
    X(BK_ERR_INTERNAL, -12, "internal error")                                          \
    X(BK_ERR_DAMAGED, -13, "damaged output file")                                       \
    X(BK_ERR_LIMIT, -14, "an output limit was reached")

typedef enum bk_status {
#define BK_STATUS_ENUM(name, value, text) name = value,
    BK_STATUS_LIST(BK_STATUS_ENUM)
#undef BK_STATUS_ENUM
} bk_status;

/* Text for a status code; never NULL. */
const char *bk_strerror(int status);

#define BK_ERROR_MESSAGE_LEN 2048

typedef struct bk_error {
    int status;                          /* last failure code, BK_OK when clear */
    char message[BK_ERROR_MESSAGE_LEN];  /* user-facing text, e.g. "a.ini:12: [run] t_end: ..." */
    const char *src_file;                /* where in bksim the failure was raised */
    int src_line;
    const char *src_func;
} bk_error;

void bk_error_clear(bk_error *err);

/* Record a failure (printf-style message) and return status.  err may be NULL.
 * Use through BK_FAIL so the source location is filled in. */
int bk_error_set(bk_error *err, int status, const char *src_file, int src_line,
                 const char *src_func, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));

#define BK_FAIL(err, status, ...) \
    bk_error_set((err), (status), __FILE__, __LINE__, __func__, __VA_ARGS__)

#endif
