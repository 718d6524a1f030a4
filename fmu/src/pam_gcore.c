/* The FMU core of a generated assembly; see pam_gcore.h.  A unity build: the engine, and through it the
 * generated model, are compiled into this file. */
#include "pam_engine.c"
#include "pam_gauss.h"
#include "pam_fmu_core.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PAM_ARRAY(n) ((n) > 0 ? (n) : 1)

/* ------------------------------------------------------------ the model's vectors in r[] */

#ifdef PAM_NK
/* The FMU's parameters are not the model's (PAM_NK knobs: a muscle's parameters, its run-time choices, the
 * load's mass): the generated map pm_kmap derives the model's from them, as Python does. */
static void gather_knobs(const PamCore *c, double *k) {
    int j;
    for (j = 0; j < PAM_NK; j++) k[j] = PAM_K_INT[j] ? (double)c->i[PAM_K_INDEX[j]] : c->r[PAM_K_INDEX[j]];
}
#endif

static void gather_parameters(const PamCore *c, double *p) {
#ifdef PAM_NK
    double k[PAM_NK];
    gather_knobs(c, k);
    pm_kmap(k, p);
#else
    int j;
    for (j = 0; j < PM_NP; j++) p[j] = c->r[PAM_P_R[j]];
#endif
}

static void gather_all(const PamCore *c, double *x, double *u, double *p) {
    int k;
    for (k = 0; k < PM_NS; k++) x[k] = c->r[PAM_STATE_R[k]];
    for (k = 0; k < PM_NU; k++) u[k] = c->r[PAM_U_R[k]];
    gather_parameters(c, p);
}

static int scheduled(const PamCore *c) {
    return PAM_NSIG > 0 && c->i[I_input_source] == PAM_INPUT_SOURCE_SCENARIO;
}

void pam_reset(PamCore *c) {
    int k;
    for (k = 0; k < PAM_NVARS; k++) {
        if (PAM_VARS[k].kind == 'r') c->r[PAM_VARS[k].index] = PAM_VARS[k].start;
        else if (PAM_VARS[k].kind) c->i[PAM_VARS[k].index] = (int32_t)PAM_VARS[k].start;
    }
    c->time_s = 0.0;
    c->mode = 0;
    c->inputs_changed = 0;
    c->h_s = 1e-4;
    c->n_steps = c->n_rhs = c->n_events = 0;
    c->event_time_s = 0.0;
    c->inputs_set = 0;
    c->hold_until_s = -HUGE_VAL; /* no hold, as pam_engine_reset leaves it */
    c->since_s = -HUGE_VAL;
    c->n_zero = 0;
    c->stiff = c->n_stiff = c->n_nonstiff = c->n_slow = 0;
    c->h_stiff_s = 0.0;
}

#ifdef PAM_NCHECKS
/* The generated checks (pm_checks: per check 1 if it holds, then the values its message shows), over the
 * knobs and the inputs; `vr` with `value`: an input about to be set, and only its checks (0: every check
 * that is not an input's).  -1 (each failure logged) if one fails. */
static int run_checks(PamCore *c, unsigned vr, double value) {
    double k[PAM_NK], u[PAM_ARRAY(PM_NU)], out[PAM_NCHECKS + PAM_NCHECK_VALUES];
    int j, bad = 0;
    gather_knobs(c, k);
    for (j = 0; j < PM_NU; j++) u[j] = c->r[PAM_U_R[j]];
    for (j = 0; j < PAM_NK && vr; j++)
        if (PAM_K_VR[j] == vr) k[j] = value;
    for (j = 0; j < PM_NU && vr; j++)
        if (PAM_U_VR[j] == vr) u[j] = value;
    pm_checks(k, u, out);
    for (j = 0; j < PAM_NCHECKS; j++) {
        const PamCheck *check = &PAM_CHECKS[j];
        const double *v = out + PAM_NCHECKS + check->first_value;
        if (check->input_vr != vr || out[j] != 0.0) continue;
        pam_logf(c, PAM_LOG_ERROR, check->message, v[0], v[1], v[2], v[3]);
        bad = -1;
    }
    return bad;
}
#endif

int pam_check_value(PamCore *c, unsigned vr, double value) {
    if (pam_check_own_range(c, vr, value)) return -1;
#ifdef PAM_NCHECKS
    if (vr >= 1 && vr <= PAM_NVARS && PAM_VARS[vr - 1].causality == PAM_INPUT) return run_checks(c, vr, value);
#endif
    return 0;
}

int pam_check_parameters(PamCore *c) {
    int bad = 0, k;
    if (pam_check_parameter_ranges(c)) return -1;
#ifdef PAM_NCHECKS
    if (run_checks(c, 0, 0.0)) bad = -1;
#endif
    if (c->i[I_input_source] == PAM_INPUT_SOURCE_SCENARIO && pam_check_signals(c)) bad = -1;
    for (k = 0; k < PAM_NVARS; k++)
        if (PAM_VARS[k].causality == PAM_INPUT && pam_check_value(c, (unsigned)k + 1, c->r[PAM_VARS[k].index])) bad = -1;
    return bad;
}

/* ------------------------------------------------------------ the engine's view of the core */

/* The engine and what its callbacks need: the core it reads its signals from, and the quadratures. */
typedef struct {
    PamEngine e;
    PamCore *core;
    PamEngineInputs inputs;
    double quad[PAM_ARRAY(PM_NQ)];
    double gl_weight[GL_N];
} EngineRun;

static void run_inputs_at(void *env, double t_s, int left, double *u) {
    EngineRun *run = (EngineRun *)env;
    int k;
    pam_inputs_at(run->core, t_s, left);
    for (k = 0; k < PM_NU; k++) u[k] = run->core->r[PAM_U_R[k]];
}

static double run_next_breakpoint(void *env, double t_s) {
    return pam_next_breakpoint(((EngineRun *)env)->core, t_s);
}

static int run_constant_after(void *env, double t_s) { return pam_inputs_constant(((EngineRun *)env)->core, t_s); }

/* Each accepted step adds its quadratures (the work integrals, outside the engine's error control): a
 * 5-point Gauss rule on the step's dense output, the inputs at each node. */
static void run_quadrature(void *env, double t0, double t1, double h, const double *y0, const PamStages *s) {
    EngineRun *run = (EngineRun *)env;
    PamEngine *e = &run->e;
    double span = t1 - t0, y[PAM_ARRAY(PM_NX)], dq[PAM_ARRAY(PM_NQ)];
    int k, q;
    if (PM_NQ == 0 || !(span > 0.0) || PM_MODE_QUAD_ZERO[e->mode]) return;
    for (k = 0; k < GL_N; k++) {
        double tau = t0 + GL_NODE[k] * span;
        if (s) dp_dense(s, y0, h, (tau - t0) / h, y);
        else memcpy(y, y0, sizeof y);
        inputs_at(e, tau, 1);
        pm_fq(e->mode, y, e->u, e->p, dq);
        for (q = 0; q < PM_NQ; q++) run->quad[q] += span * run->gl_weight[k] * dq[q];
    }
}

static void engine_load(PamCore *c, EngineRun *run) {
    PamEngine *e = &run->e;
    double x[PAM_ARRAY(PM_NS)], A[GL_N][GL_N];
    int k, j;
    pam_engine_reset(e);
    gather_all(c, x, e->u, e->p);
    for (k = 0; k < PM_NX; k++) e->x[k] = x[PM_DYNAMIC[k]];
    for (k = 0; k < PM_NQ; k++) run->quad[k] = x[PM_QUADRATURE[k]];
    e->mode = c->mode;
    e->time_s = c->time_s;
    e->rtol = c->r[R_cs_relative_tolerance];
    e->max_step_s = c->r[R_cs_max_step_s];
    e->max_steps = c->i[I_cs_max_internal_steps];
    e->h_s = c->h_s;
    e->inputs_changed = c->inputs_changed;
    e->hold_until_s = c->hold_until_s;
    e->since_s = c->since_s;
    e->n_zero = c->n_zero;
    e->stiff = c->stiff;
    e->n_stiff = c->n_stiff;
    e->n_nonstiff = c->n_nonstiff;
    e->n_slow = c->n_slow;
    e->h_stiff_s = c->h_stiff_s;
    e->n_steps = c->n_steps;
    e->n_rhs = c->n_rhs;
    e->n_events = c->n_events;
    e->log = c->log;
    e->log_env = c->log_env;
    run->core = c;
    run->inputs.at = run_inputs_at;
    run->inputs.next_breakpoint = run_next_breakpoint;
    run->inputs.constant_after = run_constant_after;
    run->inputs.env = run;
    e->inputs = scheduled(c) ? &run->inputs : NULL;
    e->on_step = run_quadrature;
    e->step_env = run;
    gauss_primitives(A);
    for (k = 0; k < GL_N; k++)
        for (run->gl_weight[k] = 0.0, j = 0; j < GL_N; j++) run->gl_weight[k] += A[k][j];
}

static void engine_store(PamCore *c, const EngineRun *run) {
    const PamEngine *e = &run->e;
    int k;
    for (k = 0; k < PM_NX; k++) c->r[PAM_STATE_R[PM_DYNAMIC[k]]] = e->x[k];
    for (k = 0; k < PM_NQ; k++) c->r[PAM_STATE_R[PM_QUADRATURE[k]]] = run->quad[k];
    for (k = 0; k < PM_NU; k++) c->r[PAM_U_R[k]] = e->u[k];
    c->mode = e->mode;
    c->h_s = e->h_s;
    c->inputs_changed = e->inputs_changed;
    c->hold_until_s = e->hold_until_s;
    c->since_s = e->since_s;
    c->n_zero = e->n_zero;
    c->stiff = e->stiff;
    c->n_stiff = e->n_stiff;
    c->n_nonstiff = e->n_nonstiff;
    c->n_slow = e->n_slow;
    c->h_stiff_s = e->h_stiff_s;
    c->n_steps = e->n_steps;
    c->n_rhs = e->n_rhs;
    c->n_events = e->n_events;
}

/* ------------------------------------------------------------ evaluation */

void pam_evaluate(PamCore *c) {
    double x[PAM_ARRAY(PM_NS)], u[PAM_ARRAY(PM_NU)], p[PAM_ARRAY(PM_NP)], xd[PAM_ARRAY(PM_NX)];
    double f[PAM_ARRAY(PM_NX)], fq[PAM_ARRAY(PM_NQ)], z[PAM_ARRAY(PM_NZ)], y[PAM_ARRAY(PM_NY)];
    int k;
    gather_all(c, x, u, p);
    for (k = 0; k < PM_NX; k++) xd[k] = x[PM_DYNAMIC[k]];
    pm_f(c->mode, xd, u, p, f);
    pm_fq(c->mode, xd, u, p, fq);
    pm_z(c->mode, xd, u, p, z);
    pm_y(c->mode, x, u, p, y);
    for (k = 0; k < PM_NX; k++) c->r[PAM_DERIV_R[PM_DYNAMIC[k]]] = f[k];
    for (k = 0; k < PM_NQ; k++) c->r[PAM_DERIV_R[PM_QUADRATURE[k]]] = fq[k];
    for (k = 0; k < PM_NZ; k++) c->r[PAM_INDICATOR_R[k]] = z[k];
    /* An output that is also a state or a parameter is that variable (PAM_Y_R -1). */
    for (k = 0; k < PM_NY; k++)
        if (PAM_Y_R[k] >= 0) c->r[PAM_Y_R[k]] = y[k];
    if (PAM_I_MODE >= 0) c->i[PAM_I_MODE] = PM_MODE_VALUE[c->mode];
}

/* The initial states and mode from the parameters and the inputs as they are. */
static void derive_start(PamCore *c) {
    EngineRun run;
    int k;
    engine_load(c, &run);
    pam_engine_initialize(&run.e);
    for (k = 0; k < PM_NS; k++) c->r[PAM_STATE_R[k]] = run.e.q_start[k];
    c->mode = run.e.mode;
    c->inputs_changed = 0;
    pam_evaluate(c);
}

void pam_initialize(PamCore *c) {
    pam_apply_signals(c, c->time_s, 0, c->inputs_set); /* the ones the importer set are checked equal */
    derive_start(c);
}

void pam_note_table_edge(PamCore *c) { (void)c; }

/* Model exchange: the importer's solver decides what follows.  An event's jump and mode are the engine's
 * (at_event), with its hold of a slip that ended where it began: the model is held, whatever its forces do,
 * until the hold's end, a time event (pam_next_event_time), where its mode is decided again from its forces.
 * An event inside a hold (an indicator the held forces cross, a breakpoint) changes nothing; the indicator
 * stays on its side, so the importer meets it once.  An event where no indicator is at or below zero is a
 * time event (a breakpoint): there, as in the engine, a held model's mode is decided again and the count of
 * slips that ended where they began is left as it is. */
int pam_event_update(PamCore *c) {
    EngineRun run;
    double t = c->event_time_s, x_before[PAM_ARRAY(PM_NX)];
    int zero_length = 0, jumped;
    engine_load(c, &run);
    memcpy(x_before, run.e.x, sizeof x_before);
    if (holding(&run.e, t)) {
        /* held */
    } else if (run.e.hold_until_s > -HUGE_VAL) {
        run.e.hold_until_s = -HUGE_VAL;
        run.e.since_s = t;
        recheck_held(&run.e, t, run.e.x);
    } else if (fired_indicators(&run.e, run.e.x) == 0) {
        /* A time event (a breakpoint): a held model's mode decided again, as the engine does there. */
        run.e.since_s = t;
        recheck_held(&run.e, t, run.e.x);
    } else {
        at_event(&run.e, t, run.e.x, &zero_length);
    }
    jumped = memcmp(x_before, run.e.x, sizeof x_before) != 0;
    engine_store(c, &run);
    c->inputs_changed = 0;
    pam_evaluate(c);
    return jumped;
}

double pam_next_event_time(const PamCore *c, double t_s) {
    double next = pam_next_breakpoint(c, t_s);
    return c->hold_until_s > t_s ? fmin(next, c->hold_until_s) : next;
}

int pam_do_step(PamCore *c, double t_end) {
    EngineRun run;
    int failed;
    engine_load(c, &run);
    failed = pam_engine_do_step(&run.e, t_end);
    engine_store(c, &run);
    c->time_s = run.e.time_s;
    if (!failed) c->time_s = t_end;
    pam_inputs_at(c, c->time_s, 0);
    pam_evaluate(c);
    return failed ? -1 : 0;
}

/* ------------------------------------------------------------ directional derivatives */

/* Where variable `vr` sits in the exact Jacobians of pam_model.c: PAM_DD_KIND (PAM_DD_STATE, ...) and
 * its place in its vector (PAM_DD_INDEX); 0 for a variable that is none of these. */
static int dd_kind(unsigned vr) { return vr >= 1 && vr <= PAM_NVARS ? PAM_DD_KIND[vr - 1] : PAM_DD_NONE; }

/* Adds `seed` to the entry of the seed vectors (dx, du, dp, dk) that variable `vr` is: a state (outside
 * initialisation), an input, a parameter (in initialisation) or a knob (in initialisation, or at any time
 * for an input knob, the load's mass); -1 for any other known. */
static int add_seed(unsigned vr, double seed, int initializing, double *dx, double *du, double *dp, double *dk) {
    int kind = dd_kind(vr), at = kind == PAM_DD_NONE ? 0 : PAM_DD_INDEX[vr - 1];
    if (kind == PAM_DD_STATE && !initializing) dx[at] += seed;
    else if (kind == PAM_DD_INPUT) du[at] += seed;
    else if (kind == PAM_DD_PARAMETER && initializing) dp[at] += seed;
    else if (kind == PAM_DD_KNOB && (initializing || PAM_VARS[vr - 1].causality == PAM_INPUT)) dk[at] += seed;
    else return -1;
    return 0;
}

/* The place of an unknown in [der(x); y], or -2 - k for state k (its own derivative is the identity, or in
 * initialisation its initial value's). */
static int unknown_row(unsigned vr) {
    int kind = dd_kind(vr), at = kind == PAM_DD_NONE ? 0 : PAM_DD_INDEX[vr - 1];
    if (kind == PAM_DD_DERIVATIVE) return at;
    if (kind == PAM_DD_OUTPUT) return PM_NS + at;
    if (kind == PAM_DD_STATE) return -2 - at;
    return -1;
}

#ifndef PAM_NK
#define PAM_NK 0
#endif

/* One forward-mode pass of the generated derivatives along the seed the knowns make: in initialisation the
 * states follow the parameters and inputs (dx = d x0 along the seed), and knobs move the parameters their
 * map derives. */
int pam_directional_derivative(PamCore *c, const unsigned *unknowns, int n_unknowns, const unsigned *knowns,
                               int n_knowns, const double *seed, double *sensitivity, int initializing) {
    double x[PAM_ARRAY(PM_NS)], u[PAM_ARRAY(PM_NU)], p[PAM_ARRAY(PM_NP)];
    double dx[PAM_ARRAY(PM_NS)] = {0}, du[PAM_ARRAY(PM_NU)] = {0}, dp[PAM_ARRAY(PM_NP)] = {0};
    double dk[PAM_ARRAY(PAM_NK)] = {0}, out[PAM_ARRAY(PM_NS + PM_NY)];
    int k, a;
    for (k = 0; k < n_knowns; k++)
        if (add_seed(knowns[k], seed[k], initializing, dx, du, dp, dk)) return -1;
    for (a = 0; a < n_unknowns; a++)
        if (unknown_row(unknowns[a]) == -1) return -1;
    gather_all(c, x, u, p);
#if PAM_NK > 0
    {
        double kn[PAM_NK], dpk[PAM_ARRAY(PM_NP)];
        gather_knobs(c, kn);
        pm_dkmap(kn, dk, dpk);
        for (k = 0; k < PM_NP; k++) dp[k] += dpk[k];
    }
#endif
    if (initializing) pm_dx0(u, p, du, dp, dx);
    pm_dir(c->mode, x, u, p, dx, du, dp, out);
    for (a = 0; a < n_unknowns; a++) {
        int row = unknown_row(unknowns[a]);
        sensitivity[a] = row <= -2 ? dx[-2 - row] : out[row];
    }
    return 0;
}

/* ------------------------------------------------------------ FMU state */

const char *pam_state_invalid(const PamCore *c) {
    if (c->mode < 0 || c->mode >= PM_NMODES) return "its mode is not one of this model's";
    if (!isfinite(c->time_s) || !(c->h_s > 0.0) || !isfinite(c->h_s)) return "its time or step is not finite";
    if (c->n_steps < 0 || c->n_rhs < 0 || c->n_events < 0) return "a count is negative";
    return NULL;
}

void pam_adopt_state(PamCore *c, const PamCore *from) {
    PamLogFn log = c->log;
    void *env = c->log_env;
    *c = *from;
    c->log = log;
    c->log_env = env;
}
