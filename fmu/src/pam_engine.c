/* pamsim generic engine; see pam_engine.h.  The integrator, event location and mode switching of
 * pamsim's first C core (written by hand, since removed), with every physical quantity taken from the
 * generated model. */
#include "pam_engine.h"
#include "pam_dopri.h"
#include "pam_rosenbrock.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* A legitimate cascade of events at one instant (a stop, a stick, a release) needs a handful. */
#define PAM_ENGINE_MAX_ZERO_LENGTH 50
/* A held model's step longer than max_step_s is checked at this many points of its dense output. */
#define PAM_ENGINE_HELD_CHECKS 16

static void engine_logf(PamEngine *e, int level, const char *fmt, ...) {
    char buf[512];
    va_list ap;
    if (!e->log) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    e->log(e->log_env, level, buf);
}

static int held(const PamEngine *e) { return PM_MODE_HELD[e->mode]; }

/* The inputs at t_s (from the left of t_s if `left`) when they follow signals; else they stay as set. */
static void inputs_at(PamEngine *e, double t_s, int left) {
    if (e->inputs) e->inputs->at(e->inputs->env, t_s, left, e->u);
}

/* The end of the piece of [t_s, t_end] the integrator crosses next: t_end, or the first breakpoint of
 * the signals before it (they are smooth in between). */
static double piece_end(const PamEngine *e, double t_s, double t_end) {
    return e->inputs ? fmin(t_end, e->inputs->next_breakpoint(e->inputs->env, t_s)) : t_end;
}

/* 1 if no input changes from t_s to the end of its piece. */
static int inputs_constant(const PamEngine *e, double t_s) {
    return !e->inputs || e->inputs->constant_after(e->inputs->env, t_s);
}

static void rhs(PamEngine *e, const double *y, double *dy) {
    e->n_rhs++;
    pm_f(e->mode, y, e->u, e->p, dy);
}

/* The smallest of the indicators in `which` (bit k: indicator k) at y. */
static double min_indicator_of(const PamEngine *e, const double *y, unsigned which) {
    double z[PM_NZ > 0 ? PM_NZ : 1], m = INFINITY;
    int k;
    if (PM_NZ == 0) return m;
    pm_z(e->mode, y, e->u, e->p, z);
    for (k = 0; k < PM_NZ; k++)
        if ((which >> k) & 1u) m = fmin(m, z[k]);
    return m;
}

static double min_indicator(const PamEngine *e, const double *y) { return min_indicator_of(e, y, ~0u); }

static int mode_of(double value) {
    int k = pm_mode_index(value);
    return k < 0 ? 0 : k;
}

/* The mode of a held model decided afresh from its forces (a moving one keeps its mode). */
static int rest_mode(const PamEngine *e, int mode, const double *y) {
    double q = PM_MODE_VALUE[mode];
    pm_rest(mode, y, e->u, e->p, &q);
    return mode_of(q);
}

/* The jump at an event whose indicators `fired` (bit k: indicator k) have crossed: new states in y,
 * new mode in e->mode (*jump_mode: the jump's own, before the held mode is decided afresh); returns 1
 * if a state changed. */
static int transition(PamEngine *e, double *y, unsigned fired, int *jump_mode) {
    double flags[PM_NZ > 0 ? PM_NZ : 1], next[PM_NX], q = PM_MODE_VALUE[e->mode];
    int k, jumped = 0;
    for (k = 0; k < PM_NZ; k++) flags[k] = (fired >> k) & 1u ? 1.0 : 0.0;
    pm_tr(e->mode, y, e->u, e->p, flags, next, &q);
    for (k = 0; k < PM_NX; k++) {
        jumped |= next[k] != y[k];
        y[k] = next[k];
    }
    *jump_mode = mode_of(q);
    e->mode = rest_mode(e, *jump_mode, y);
    return jumped;
}

/* The indicators at or below zero in z, bit k for indicator k (the mask an event's transition takes). */
static unsigned fired_of(const double *z) {
    unsigned fired = 0;
    int k;
    for (k = 0; k < PM_NZ; k++)
        if (z[k] <= 0.0) fired |= 1u << k;
    return fired;
}

/* fired_of the indicators at y, in the current mode with the current inputs. */
static unsigned fired_indicators(const PamEngine *e, const double *y) {
    double z[PM_NZ > 0 ? PM_NZ : 1];
    if (PM_NZ == 0) return 0;
    pm_z(e->mode, y, e->u, e->p, z);
    return fired_of(z);
}

void pam_engine_reset(PamEngine *e) {
    memset(e, 0, sizeof *e);
    e->hold_until_s = -HUGE_VAL;
    e->since_s = -HUGE_VAL;
    e->rtol = 1e-6;
    e->max_step_s = 1e-3;
    e->max_steps = 1000000;
    e->h_s = 1e-4;
    e->stiff_switch = 1;
}

/* Initial states from the inputs and parameters, and the mode decided from the forces there. */
void pam_engine_initialize(PamEngine *e) {
    double x[PM_NS > 0 ? PM_NS : 1], q0 = 0.0;
    int k;
    pm_x0(e->u, e->p, x, &q0);
    memcpy(e->q_start, x, sizeof e->q_start);
    for (k = 0; k < PM_NX; k++) e->x[k] = x[PM_DYNAMIC[k]];
    e->mode = rest_mode(e, mode_of(q0), e->x);
    e->inputs_changed = 0;
}

/* The nodes of the tableau of pam_dopri.h, where inputs that follow signals are evaluated. */
static const double DP_NODE[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};

/* The scaled RMS norm of the error estimate d of a step from y0 to y1 (absolute: rtol times each nominal). */
static double error_norm(const PamEngine *e, const double *y0, const double *y1, const double *d) {
    double err = 0.0;
    int n;
    for (n = 0; n < PM_NX; n++) {
        double sc = e->rtol * PM_NOMINAL[n] + e->rtol * fmax(fabs(y0[n]), fabs(y1[n]));
        err += (d[n] / sc) * (d[n] / sc);
    }
    return PM_NX > 0 ? sqrt(err / PM_NX) : 0.0;
}

/* One trial step from t0; returns the scaled RMS error norm.  k[0] must hold f(y0).  Inputs that
 * follow signals are left at their values from the left of t0 + h. */
static double dp_step(PamEngine *e, double t0, const double *y0, double h, PamStages *s, double *y1, double *y6) {
    double yt[PM_NX], d[PM_NX];
    int st, j, n;
    s->poly = 0;
    for (st = 1; st < 7; st++) {
        for (n = 0; n < PM_NX; n++) {
            double acc = 0.0;
            for (j = 0; j < st; j++) acc += DP_A[st][j] * s->k[j][n];
            yt[n] = y0[n] + h * acc;
        }
        if (st == 5) memcpy(y6, yt, sizeof yt);
        inputs_at(e, t0 + DP_NODE[st] * h, 1);
        rhs(e, yt, s->k[st]);
    }
    for (n = 0; n < PM_NX; n++) {
        double acc = 0.0;
        y1[n] = yt[n]; /* stage 7 is evaluated at the 5th-order solution (FSAL) */
        for (st = 0; st < 7; st++) acc += DP_E[st] * s->k[st][n];
        d[n] = h * acc;
    }
    return error_norm(e, y0, y1, d); /* no integrated state: only quadratures, exact per step */
}

static void dp_dense(const PamStages *s, const double *y0, double h, double th, double *y) {
    double pw[4] = {th, th * th, th * th * th, th * th * th * th};
    int n, st, j;
    if (s->poly) {
        for (n = 0; n < PM_NX; n++)
            y[n] = y0[n] + th * (s->q[0][n] + th * (s->q[1][n] + th * (s->q[2][n] + th * s->q[3][n])));
        return;
    }
    for (n = 0; n < PM_NX; n++) {
        double acc = 0.0;
        for (st = 0; st < 7; st++) {
            double q = 0.0;
            for (j = 0; j < 4; j++) q += DP_P[st][j] * pw[j];
            acc += s->k[st][n] * q;
        }
        y[n] = y0[n] + h * acc;
    }
}

/* One trial Rosenbrock step (pam_rosenbrock.h's tableau r) of a model whose inputs are constant over it; returns the
 * scaled RMS error norm (infinite where the stage matrix is singular).  s->k[0] must hold f(y0).  An
 * accepted step (norm <= 1) also evaluates f(y1) into s->k[6], the next step's first, and leaves as its
 * dense output the cubic Hermite interpolant of y0, y1 and their derivatives. */
static double ros_step(PamEngine *e, const RosTableau *r, const double *y0, double h, PamStages *s, double *y1) {
    double jac[PM_NX * PM_NX > 0 ? PM_NX * PM_NX : 1], a[PM_NX * PM_NX > 0 ? PM_NX * PM_NX : 1];
    double K[6][PM_NX > 0 ? PM_NX : 1], f[PM_NX > 0 ? PM_NX : 1], yt[PM_NX > 0 ? PM_NX : 1], err;
    int piv[PM_NX > 0 ? PM_NX : 1], i, j, n, m;
    pm_jac(e->mode, y0, e->u, e->p, jac); /* column-major: d f_n / d y_m at jac[m * PM_NX + n] */
    e->n_jacobians++;
    for (n = 0; n < PM_NX; n++)
        for (m = 0; m < PM_NX; m++) a[n * PM_NX + m] = (n == m ? 1.0 / (h * r->gamma) : 0.0) - jac[m * PM_NX + n];
    if (!ros_lu(a, piv, PM_NX)) return INFINITY;
    memcpy(f, s->k[0], sizeof f);
    for (i = 0; i < r->stages; i++) {
        if (i > 0 && r->new_f[i]) {
            for (n = 0; n < PM_NX; n++) {
                double acc = 0.0;
                for (j = 0; j < i; j++) acc += r->a[i][j] * K[j][n];
                yt[n] = y0[n] + acc;
            }
            rhs(e, yt, f);
        }
        for (n = 0; n < PM_NX; n++) {
            double acc = 0.0;
            for (j = 0; j < i; j++) acc += r->c[i][j] * K[j][n];
            K[i][n] = f[n] + acc / h;
        }
        ros_solve(a, piv, PM_NX, K[i]);
    }
    for (n = 0; n < PM_NX; n++) {
        double acc = 0.0, d = 0.0;
        for (i = 0; i < r->stages; i++) {
            acc += r->m[i] * K[i][n];
            d += r->e[i] * K[i][n];
        }
        y1[n] = y0[n] + acc;
        yt[n] = d;
    }
    err = error_norm(e, y0, y1, yt);
    if (!(err <= 1.0)) return err;
    rhs(e, y1, s->k[6]);
    s->poly = 1;
    for (n = 0; n < PM_NX; n++) {
        double dy = y1[n] - y0[n], f0 = h * s->k[0][n], f1 = h * s->k[6][n];
        s->q[0][n] = f0;
        s->q[1][n] = 3.0 * dy - 2.0 * f0 - f1;
        s->q[2][n] = -2.0 * dy + f0 + f1;
        s->q[3][n] = 0.0;
    }
    return err;
}

/* After an accepted Dormand-Prince step of a held model: whether its steps are bound by stability, from
 * the estimate h |lambda| ~ h |f(y1) - f(y6)| / |y1 - y6| of its stiffest mode (stage 7 at y1, stage 6 at
 * y6), as Hairer's DOPRI5 tests it: beyond 3.25 (the method's stability boundary) at 15 steps in a row
 * it switches to Rodas4; 6 steps within it clear the count.  Rodas4's step costs a Jacobian and a
 * factorisation besides its six evaluations, so where its steps stay within twice the Dormand-Prince
 * step of the switch 5 times in a row (accuracy, not stability, binds both: a valve's flow near a pressure
 * ratio of 1 whose Jacobian changes fast) it goes back, until the mode changes (note_rosenbrock_step). */
static void test_stiffness(PamEngine *e, const PamStages *s, const double *y1, const double *y6, double h) {
    double num = 0.0, den = 0.0;
    int n;
    for (n = 0; n < PM_NX; n++) {
        double df = s->k[6][n] - s->k[5][n], dy = y1[n] - y6[n];
        num += df * df;
        den += dy * dy;
    }
    if (den > 0.0 && h * sqrt(num / den) > 3.25) {
        e->n_nonstiff = 0;
        if (++e->n_stiff >= 15) {
            e->stiff = 1;
            e->h_stiff_s = h;
            e->n_slow = 0;
        }
    } else if (++e->n_nonstiff >= 6) {
        e->n_stiff = 0;
    }
}

/* After an accepted Rodas4 step h: back to Dormand-Prince where Rodas4 does not pay (test_stiffness). */
static void note_rosenbrock_step(PamEngine *e, double h) {
    e->n_slow = h <= 2.0 * e->h_stiff_s ? e->n_slow + 1 : 0;
    if (e->n_slow >= 5) e->stiff = -1;
}

/* How far the indicator k moves when the states at y move by their absolute tolerances, one at a time
 * (the sum of the moves): a value of it closer to zero than that is below what the integration resolves. */
static double indicator_resolution(PamEngine *e, const double *y, const double *z, int k) {
    double yd[PM_NX], zd[PM_NZ > 0 ? PM_NZ : 1], r = 0.0;
    int n;
    memcpy(yd, y, sizeof yd);
    for (n = 0; n < PM_NX; n++) {
        yd[n] = y[n] + e->rtol * PM_NOMINAL[n];
        pm_z(e->mode, yd, e->u, e->p, zd);
        r += fabs(zd[k] - z[k]);
        yd[n] = y[n];
    }
    return r;
}

/* Where to look inside a moving step, as a fraction of it in (0, 1), for an indicator above zero at both
 * ends that may dip to zero and back inside it; -1 if none may.  It is below zero at the step's midpoint
 * (look there), or the parabola through its values at the ends and the midpoint has its lowest point
 * inside the step, below zero (look there).  Either by more than the indicator's resolution at the
 * midpoint (indicator_resolution): a velocity hovering far below its tolerance of zero is no stick.  z0:
 * the indicators at the step's start; z1 at its end.  pamsim.stepping._may_dip is the python backend's. */
static double may_dip(PamEngine *e, const PamStages *s, double t, const double *y, double h, const double *z0,
                      const double *z1) {
    double ym[PM_NX], zm[PM_NZ > 0 ? PM_NZ : 1];
    int k;
    dp_dense(s, y, h, 0.5, ym);
    inputs_at(e, t + 0.5 * h, 1);
    pm_z(e->mode, ym, e->u, e->p, zm);
    for (k = 0; k < PM_NZ; k++) {
        double a = 2.0 * (z0[k] + z1[k] - 2.0 * zm[k]), b = z1[k] - z0[k] - a; /* a th^2 + b th + z0 */
        double th = 0.5, low = zm[k];
        if (!(z0[k] > 0.0 && z1[k] > 0.0)) continue;
        if (a > 0.0 && b < 0.0 && -b < 2.0 * a && z0[k] - b * b / (4.0 * a) < low) {
            th = -b / (2.0 * a);
            low = z0[k] - b * b / (4.0 * a);
        }
        if (low < 0.0 && -low > indicator_resolution(e, ym, zm, k)) return th;
    }
    return -1.0;
}

/* Where an indicator first reaches zero over an accepted step, as a fraction of the step in
 * (lo, hi], and which indicators are at or below zero at hi (0 if none is).  The indicators at the step's
 * end go to z1.  A moving step is checked at its end, and, given the indicators at its start (z0, NULL if
 * unknown), at PAM_ENGINE_HELD_CHECKS points of its dense output and where may_dip looks, if an indicator
 * may dip to zero and back inside it: under PWM a load comes to rest for a few milliseconds between two
 * pulses, a stick that a step of that length crossed and came back from, its velocity positive at both
 * ends.  A held model's step is not limited by max_step_s (its states approach their sources
 * monotonically, so its force margins seldom turn back), so a long one is also checked at
 * PAM_ENGINE_HELD_CHECKS points of its dense output.  As in solve_ivp and CVODE, an indicator crosses
 * where its sign changes between two checked points: one that dips below zero and back between them is
 * no event, even where another indicator's crossing brings the root finding there.  A free swing that
 * turns back at its stop, grazing it, so records the turn (the stop, if the turn lies beyond it, as
 * at_event decides) where the dense output puts it, instead of an impact whose time moves with the square
 * root of the integration error: its velocity indicator fired at the step's end, and the step is not
 * looked into for dips. */
static unsigned first_crossing(PamEngine *e, const PamStages *s, double t, const double *y, const double *y1,
                               double h, const double *z0, double *z1, double *lo, double *hi) {
    int n = (held(e) && h > e->max_step_s) ? PAM_ENGINE_HELD_CHECKS : 1, m = 0, k;
    double ye[PM_NX], dip = -1.0, at[PAM_ENGINE_HELD_CHECKS + 1];
    unsigned fired;
    if (PM_NZ == 0) return 0;
    inputs_at(e, t + h, 1);
    pm_z(e->mode, y1, e->u, e->p, z1);
    fired = fired_of(z1);
    if (n == 1 && !fired && z0 != NULL && !held(e)) {
        dip = may_dip(e, s, t, y, h, z0, z1);
        if (dip > 0.0) n = PAM_ENGINE_HELD_CHECKS;
    }
    /* the points inside the step, in order: k / n, and the dip's between them */
    for (k = 1; k <= n; k++) {
        double th = (double)k / n;
        if (dip > (m ? at[m - 1] : 0.0) && dip < th) at[m++] = dip;
        if (k < n) at[m++] = th;
    }
    for (k = 0; k < m; k++) {
        unsigned inside;
        dp_dense(s, y, h, at[k], ye);
        inputs_at(e, t + at[k] * h, 1);
        inside = fired_indicators(e, ye);
        if (inside) {
            *lo = k ? at[k - 1] : 0.0;
            *hi = at[k];
            return inside;
        }
    }
    inputs_at(e, t + h, 1);
    *lo = m ? at[m - 1] : 0.0;
    *hi = 1.0;
    return fired;
}

/* The smallest of the indicators `which` at the fraction th of the accepted step from t (y1 at its end). */
static double indicator_on_step(PamEngine *e, const PamStages *s, double t, const double *y, const double *y1,
                                double h, unsigned which, double th) {
    double ye[PM_NX];
    if (th >= 1.0) {
        inputs_at(e, t + h, 1);
        return min_indicator_of(e, y1, which);
    }
    dp_dense(s, y, h, th, ye);
    inputs_at(e, t + th * h, 1);
    return min_indicator_of(e, ye, which);
}

/* Narrows [lo, hi] (fractions of the step; the indicators `which` above zero at lo, at or below it at hi)
 * onto their first crossing on the dense output, to 1e-15 of the time, keeping hi on the far side so that
 * the event test holds there.  The Illinois variant of regula falsi: the dense output is a smooth
 * polynomial, so it needs a handful of evaluations where bisection needed some fifty, and an event's cost
 * was mostly its location (ten Maxwell-slip elements switch tens of times a second).  It halves the value
 * kept at an end that stays twice, and bisects where the secant leaves the bracket. */
static void locate_crossing(PamEngine *e, const PamStages *s, double t, const double *y, const double *y1,
                            double h, unsigned which, double *lo, double *hi) {
    double g_lo = indicator_on_step(e, s, t, y, y1, h, which, *lo);
    double g_hi = indicator_on_step(e, s, t, y, y1, h, which, *hi);
    int it, kept = 0; /* +1: lo was kept last time, -1: hi was */
    for (it = 0; it < 100 && (*hi - *lo) * h > 1e-15 * fmax(1.0, fabs(t)); it++) {
        double mid = g_lo > 0.0 && g_hi <= 0.0 ? (*lo * g_hi - *hi * g_lo) / (g_hi - g_lo) : 0.5 * (*lo + *hi), g;
        if (!(mid > *lo && mid < *hi)) mid = 0.5 * (*lo + *hi);
        g = indicator_on_step(e, s, t, y, y1, h, which, mid);
        if (g <= 0.0) {
            *hi = mid;
            g_hi = g;
            if (kept == 1) g_lo *= 0.5;
            kept = 1;
        } else {
            *lo = mid;
            g_lo = g;
            if (kept == -1) g_hi *= 0.5;
            kept = -1;
        }
    }
}

/* A held model within the integrator's tolerance of the steady state it approaches is set to it
 * (the model's settle function), so that its derivatives are exactly zero: the rest of an
 * exponential approach is below the tolerance, and an explicit integrator would follow it in steps
 * of its time constant for ever.  Not where the change would cross an event indicator.  Returns 1
 * if it changed y. */
static int settle(PamEngine *e, double *y) {
    double settled[PM_NX];
    int k, changed = 0;
    if (!held(e)) return 0;
    pm_settle(e->mode, y, e->u, e->p, e->rtol, settled);
    for (k = 0; k < PM_NX; k++) changed |= settled[k] != y[k];
    if (!changed || min_indicator(e, settled) <= 0.0) return 0;
    memcpy(y, settled, sizeof settled);
    return 1;
}

/* Leaves the engine at the last instant reached and fails. */
static int step_failed(PamEngine *e, double t, const double *y) {
    e->time_s = t;
    memcpy(e->x, y, sizeof e->x);
    return -1;
}

/* The first hold [s] of a model whose slip from rest ended where it began, doubled at each repetition up to
 * PAM_ENGINE_MAX_HOLD_DOUBLINGS times (pamsim.simulator._HOLD_S, the python backend's rule).  A body at rest
 * whose net force beats friction by a little, but whose forces turn as it moves (a controller venting, two
 * muscles' load-dependent frictions), slips and stops again within a time and speed below the integrator's
 * resolution; deciding its mode again from the same forces would repeat that for ever.  It is held for the
 * hold, whatever its forces do, and its mode decided again at the hold's end. */
#define PAM_ENGINE_HOLD_S 1e-9
#define PAM_ENGINE_MAX_HOLD_DOUBLINGS 29 /* the longest hold, 2^29 ns: about 0.54 s */

/* An event or a held model's new mode: counted, and the new mode tested afresh for stiffness. */
static void mode_changed(PamEngine *e) {
    e->n_events++;
    e->stiff = e->n_stiff = e->n_nonstiff = 0;
}

/* The event located at y (time t): the jump and the new mode; -1 if events make no progress. */
static int at_event(PamEngine *e, double t, double *y, int *zero_length) {
    double y_before[PM_NX];
    int old = e->mode, jumped, jump_mode;
    unsigned fired = fired_indicators(e, y);
    /* Within a hold's first length of its start: a slip that short moved the body by at most that time times
     * the velocity tolerance (python takes 1e-12 s relative; a slip from rest that turns back at once can
     * last a little longer where the forces that turn it are weak, and would then be decided again at once). */
    int instant = t - e->since_s <= fmax(1e-12 * fmax(1.0, fabs(t)), PAM_ENGINE_HOLD_S);
    memcpy(y_before, y, sizeof y_before);
    jumped = transition(e, y, fired, &jump_mode);
    e->n_zero = instant ? e->n_zero + 1 : 0;
    e->since_s = t;
    if (instant && PM_MODE_HELD[jump_mode] && !PM_MODE_HELD[old] && !held(e)) {
        e->mode = jump_mode;
        e->hold_until_s = t + ldexp(PAM_ENGINE_HOLD_S, (int)fmin(e->n_zero - 1, PAM_ENGINE_MAX_HOLD_DOUBLINGS));
    }
    if (!jumped && e->mode == old) {
        if (++*zero_length > PAM_ENGINE_MAX_ZERO_LENGTH) {
            engine_logf(e, PAM_ENGINE_ERROR, "event switching made no progress at t = %.9g s", t);
            return -1;
        }
        return 0;
    }
    *zero_length = 0;
    /* A jump within the mode (an element reaching its limit) leaves the equations, and their stiffness, as
     * they were: reset, an element at rest on its limit on a stiff node switched at every few Dormand-Prince
     * steps, whose stability-bound noise crossed the limit again before Rodas4 could take over. */
    if (e->mode != old) {
        mode_changed(e);
    } else {
        e->n_events++;
        if (e->stiff < 0) e->stiff = 0; /* Rodas4 given up on (note_rosenbrock_step): tested afresh, as before */
    }
    if (e->on_event) e->on_event(e->event_env, t, old, e->mode, fired, y_before, y);
    return 0;
}

/* 1 while a hold (PAM_ENGINE_HOLD_S) runs at t. */
static int holding(const PamEngine *e, double t) { return t < e->hold_until_s; }

/* The end of the piece from t that the integrator crosses next: piece_end's, or a running hold's end. */
static double next_piece_end(const PamEngine *e, double t, double t_end) {
    return holding(e, t) ? fmin(piece_end(e, t, t_end), e->hold_until_s) : piece_end(e, t, t_end);
}

/* A held model's mode decided again where its inputs jump or reach a breakpoint, unless a hold runs. */
static void recheck_held(PamEngine *e, double t, const double *y) {
    int old = e->mode;
    if (!held(e) || holding(e, t)) return;
    e->mode = rest_mode(e, e->mode, y);
    if (e->mode != old) mode_changed(e);
}

static int at_breakpoint(const PamEngine *e, double t_s) {
    return e->inputs && e->inputs->next_breakpoint(e->inputs->env, nextafter(t_s, -HUGE_VAL)) == t_s;
}

/* Integrate to t_end, the inputs held or following their signals; 0 on success, -1 on failure (logged),
 * which leaves time_s, the states and the mode at the last instant reached. */
int pam_engine_do_step(PamEngine *e, double t_end) {
    double y[PM_NX], y1[PM_NX], y6[PM_NX], t = e->time_s, h_max = e->max_step_s, t_piece;
    double z0[PM_NZ > 0 ? PM_NZ : 1], z1[PM_NZ > 0 ? PM_NZ : 1]; /* the indicators at a step's two ends */
    PamStages s;
    long steps = 0;
    int zero_length = 0, n, z0_known = 0;
    memcpy(y, e->x, sizeof y);
    inputs_at(e, t, 0);
    if (e->inputs_changed || at_breakpoint(e, t)) recheck_held(e, t, y);
    e->inputs_changed = 0;
    rhs(e, y, s.k[0]);
    t_piece = next_piece_end(e, t, t_end);
    /* A remainder below the time resolution (left by an event located just before t_end) is not a step. */
    while (t_end - t > 1e-13 * fmax(1.0, fabs(t_end))) {
        double h, err, factor, grow, cap, lo = 0.0, hi = 1.0;
        unsigned crossed;
        int last, at_rest = held(e), rosenbrock, stiff_able;
        if (t_piece - t <= 1e-13 * fmax(1.0, fabs(t_piece))) {
            /* A breakpoint of the signals (they take their values from the right), or a hold's end. */
            t = t_piece;
            e->since_s = t;
            inputs_at(e, t, 0);
            recheck_held(e, t, y);
            rhs(e, y, s.k[0]);
            t_piece = next_piece_end(e, t, t_end);
            z0_known = 0;
            continue;
        }
        inputs_at(e, t, 0); /* a rejected trial step left them at its end */
        if (settle(e, y)) {
            rhs(e, y, s.k[0]);
            z0_known = 0;
        }
        if (!z0_known && !held(e) && PM_NZ > 0) {
            pm_z(e->mode, y, e->u, e->p, z0);
            z0_known = 1;
        }
        /* A held model whose states do not change stays as it is while the inputs are held. */
        for (n = 0; n < PM_NX && at_rest; n++) at_rest = s.k[0][n] == 0.0;
        if (at_rest && inputs_constant(e, t)) {
            if (e->on_step) e->on_step(e->step_env, t, t_piece, 0.0, y, NULL);
            t = t_piece;
            continue;
        }
        h = fmin(held(e) ? e->h_s : fmin(e->h_s, h_max), t_piece - t);
        last = h >= t_piece - t;
        if (++steps > e->max_steps) {
            engine_logf(e, PAM_ENGINE_ERROR, "more than %ld internal steps between t = %.9g s and %.9g s",
                        e->max_steps, e->time_s, t_end);
            return step_failed(e, t, y);
        }
        if (h < 1e-14 * fmax(1.0, fabs(t))) {
            engine_logf(e, PAM_ENGINE_ERROR, "step size underflow at t = %.9g s", t);
            return step_failed(e, t, y);
        }
        stiff_able = held(e) && (e->stiff == 1 || (e->stiff_switch && e->stiff == 0)) && inputs_constant(e, t);
        rosenbrock = stiff_able && e->stiff == 1;
        err = rosenbrock ? ros_step(e, &RODAS4, y, h, &s, y1) : dp_step(e, t, y, h, &s, y1, y6);
        /* the step grows by err^(-1/(q+1)), q the order of the error estimate, at most 10 times (6 for Rodas4) */
        grow = rosenbrock ? -1.0 / RODAS4.elo : -0.2;
        cap = rosenbrock ? 6.0 : 10.0;
        if (!(err <= 1.0)) {
            e->h_s = h * (isfinite(err) ? fmax(0.2, 0.9 * pow(err, grow)) : 0.1);
            continue;
        }
        factor = err == 0.0 ? cap : fmin(cap, fmax(0.2, 0.9 * pow(err, grow)));
        if (rosenbrock) note_rosenbrock_step(e, h);
        else if (stiff_able) test_stiffness(e, &s, y1, y6, h);
        e->n_steps++;
        if (holding(e, t)) z0_known = 0;
        else if ((crossed = first_crossing(e, &s, t, y, y1, h, z0_known ? z0 : NULL, z1, &lo, &hi)) != 0) {
            /* Locate the first crossing of the indicators that crossed on the dense output; keep the
             * far side so that the event test holds. */
            double ye[PM_NX], t_event;
            locate_crossing(e, &s, t, y, y1, h, crossed, &lo, &hi);
            if (hi < 1.0) dp_dense(&s, y, h, hi, ye);
            else memcpy(ye, y1, sizeof ye);
            t_event = hi < 1.0 ? t + hi * h : (last ? t_piece : t + h);
            if (e->on_step) e->on_step(e->step_env, t, t_event, h, y, &s);
            t = t_event;
            inputs_at(e, t, 1);
            memcpy(y, ye, sizeof y);
            memcpy(e->x, y, sizeof y);
            if (at_event(e, t, y, &zero_length)) return step_failed(e, t, y);
            if (holding(e, t)) t_piece = fmin(t_piece, e->hold_until_s); /* a hold began */
            e->h_s = fmax(fmin(h * hi, h_max), 1e-6);
            rhs(e, y, s.k[0]);
            z0_known = 0;
            continue;
        }
        if (!holding(e, t)) {
            memcpy(z0, z1, sizeof z0);
            z0_known = 1;
        }
        if (e->on_step) e->on_step(e->step_env, t, last ? t_piece : t + h, h, y, &s);
        t = last ? t_piece : t + h;
        memcpy(y, y1, sizeof y);
        memcpy(s.k[0], s.k[6], sizeof s.k[0]);
        if (!last || factor < 1.0) e->h_s = h * factor;
    }
    e->time_s = t_end;
    inputs_at(e, t_end, 0);
    memcpy(e->x, y, sizeof y);
    return 0;
}
