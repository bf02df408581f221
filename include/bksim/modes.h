/* Per-block mode flags and the stick/slip machine (paper Figure 3, NOTES.md section 4).
 *
 *   STICK    -> SLIP_POS/NEG when |applied force| exceeds the static threshold, in the
 *               direction of the applied force;
 *   SLIP_POS -> at zero velocity: STICK if |applied force| <= static threshold, else slips
 *   SLIP_NEG    the way the force points (a stop and an instantaneous reversal).
 * There is no direct slip+ -> slip- without a stop. */
#ifndef BKSIM_MODES_H
#define BKSIM_MODES_H

typedef enum bk_mode {
    BK_MODE_STICK = 0,
    BK_MODE_SLIP_POS = 1,
    BK_MODE_SLIP_NEG = -1
} bk_mode;

/* Slip direction of a mode: +1, -1, or 0 when stuck. */
static inline int bk_mode_direction(bk_mode mode) { return (int)mode; }

/* "stick", "slip+", "slip-". */
const char *bk_mode_name(bk_mode mode);

/* Mode of a block whose velocity is zero at this instant, given the applied force (N) and
 * its static threshold (N).  Sticks unless |force| exceeds the threshold. */
bk_mode bk_mode_at_rest(double applied_force, double static_threshold);

/* What the root functions saw happen to a block. */
typedef enum bk_mode_event {
    BK_EVENT_STOP,      /* a slipping block's velocity reached zero */
    BK_EVENT_BREAKAWAY  /* a stuck block's |applied force| reached its static threshold */
} bk_mode_event;

/* The machine: the mode after `event`, given the applied force (N) and static threshold (N)
 * at that instant.  A breakaway slips the way the force points (the crossing was located by
 * the root finder, so the force is not re-compared with the threshold); a stop sticks or,
 * when the force exceeds the threshold, slips the way the force points. */
bk_mode bk_mode_next(bk_mode current, bk_mode_event event, double applied_force,
                     double static_threshold);

#endif
