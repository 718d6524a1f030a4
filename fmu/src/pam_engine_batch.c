/* pamsim native backend on the generic engine: many cases of one generated model in one call.
 *
 * A unity build: this file includes the engine, which includes the generated model, so the model's
 * functions can be inlined into the integrator.  Only the PAM_EXPORT functions leave the library
 * (pamsim/native/engine.py mirrors these layouts).  Each case runs from the model's initial state,
 * with inputs given over segments (held, or each following a line and a first-order lag in closed form
 * inside its segment), and is sampled on a uniform grid: every state
 * (the quadratures from each step's dense output), the mode, the events, and the extremes of every
 * output over every step end and event.  pam_engine_session.c, included at the end, runs one case
 * step by step instead.
 */
#include "pam_engine.c"

#include <stdint.h>

#include "pam_gauss.h"

#if defined(__GNUC__)
#define PAM_EXPORT __attribute__((visibility("default")))
#else
#define PAM_EXPORT
#endif

#define PAM_ENGINE_MSG 256
/* Columns per event: t, mode before, mode after (values), fired indicators (bit mask), the outputs
 * before (in the mode before) and after the jump. */
#define PAM_ENGINE_NEV (4 + 2 * PM_NY)

typedef enum { ENGINE_OK = 0, ENGINE_BAD_INPUT = 1, ENGINE_SOLVER_FAILED = 2, ENGINE_EVENTS_FULL = 3 } EngineStatus;

/* One call's cases; arrays are row-major and the offsets index the flattened per-case blocks. */
typedef struct {
    int64_t n_cases;
    const double *params;         /* n_cases x PM_NP */
    const double *rtol;           /* n_cases */
    const double *max_step_s;     /* n_cases */
    const int64_t *max_steps;     /* n_cases: internal steps per input segment */
    const int64_t *stiff_switch;  /* n_cases: 1 to step a stiff held model with Rodas4 (PamEngine.stiff_switch) */
    const double *duration_s;     /* n_cases */
    const int64_t *n_samples;     /* n_cases: samples at linspace(0, duration_s, n_samples) */
    const int64_t *sample_offset; /* n_cases: first sample of the case */
    const int64_t *n_segments;    /* n_cases: input segments; the first starts at 0 */
    const int64_t *segment_offset;
    const double *segment_t_s;    /* start of each segment */
    const double *segment_u;      /* PM_NU inputs at the start of each segment */
    const double *segment_du;     /* PM_NU x 3 per segment, or NULL (every input held): input k follows
                                   * u_k + b (t - t0) + c (exp(-(t - t0) / tau) - 1) over its segment
                                   * from t0, (b, c, tau) its three numbers (tau 0: no lag) */
    const int64_t *event_capacity;
    const int64_t *event_offset;
    double *samples;              /* out: per case a PM_NS x n_samples block (column-major), every state */
    int32_t *modes;               /* out: per sample, the mode's value */
    double *events;               /* out: event rows x PAM_ENGINE_NEV */
    int64_t *n_events;            /* out: n_cases */
    int64_t *stats;               /* out: n_cases x 4: RHS evaluations, accepted steps, segments + events, Jacobians */
    int32_t *status;              /* out: n_cases, EngineStatus */
    double *extremes;             /* out: n_cases x 2 PM_NY: each output's largest, then its smallest value */
    char *messages;               /* out: n_cases x PAM_ENGINE_MSG, the first error */
} PamEngineBatch;

typedef struct {
    PamEngine engine;
    char *message;
    double *events, *samples;
    int32_t *modes;
    int64_t capacity, n_events, n_samples, next_sample;
    double sample_step_s, duration_s;
    double quad[PM_NQ > 0 ? PM_NQ : 1]; /* the quadratures at the end of the last step */
    double gauss[GL_N][GL_N];
    double *y_max, *y_min;
    /* The segment being integrated: its start, inputs there and their change (segment_du), or NULL. */
    double seg_t0;
    const double *seg_u0, *seg_du;
    PamEngineInputs inputs;
} Run;

static void keep_first_error(void *env, int level, const char *message) {
    Run *run = (Run *)env;
    if (level == PAM_ENGINE_ERROR && run->message[0] == '\0') snprintf(run->message, PAM_ENGINE_MSG, "%s", message);
}

/* Every state, quadratures included, in the flat model's order. */
static void all_states(const double *xd, const double *quad, double *x) {
    int k;
    for (k = 0; k < PM_NX; k++) x[PM_DYNAMIC[k]] = xd[k];
    for (k = 0; k < PM_NQ; k++) x[PM_QUADRATURE[k]] = quad[k];
}

static void outputs(const Run *run, int mode, const double *xd, const double *quad, double *y) {
    double x[PM_NS > 0 ? PM_NS : 1];
    all_states(xd, quad, x);
    pm_y(mode, x, run->engine.u, run->engine.p, y);
}

static void note_extremes(Run *run, int mode, const double *xd, const double *quad) {
    double y[PM_NY > 0 ? PM_NY : 1];
    int k;
    outputs(run, mode, xd, quad, y);
    for (k = 0; k < PM_NY; k++) {
        if (y[k] > run->y_max[k]) run->y_max[k] = y[k];
        if (y[k] < run->y_min[k]) run->y_min[k] = y[k];
    }
}

/* One step's dense output as a polynomial, y(t0 + th h) = y0 + sum_j q[j] th^(j+1), factored once per
 * step rather than once per sample.  A NULL stages (a held model at rest) is the constant y0. */
typedef struct {
    double t0, h, y0[PM_NX], q[4][PM_NX];
} DensePoly;

static void dense_poly(DensePoly *d, const PamStages *s, const double *y0, double t0, double h) {
    int n, j, st;
    d->t0 = t0;
    d->h = h;
    memcpy(d->y0, y0, sizeof d->y0);
    if (s && s->poly) {
        memcpy(d->q, s->q, sizeof d->q);
        return;
    }
    for (j = 0; j < 4; j++)
        for (n = 0; n < PM_NX; n++) {
            double acc = 0.0;
            if (s)
                for (st = 0; st < 7; st++) acc += s->k[st][n] * DP_P[st][j];
            d->q[j][n] = h * acc;
        }
}

static void state_at(const DensePoly *d, double t, double *y) {
    double th = d->h > 0.0 ? (t - d->t0) / d->h : 0.0;
    int n;
    for (n = 0; n < PM_NX; n++)
        y[n] = d->y0[n] + th * (d->q[0][n] + th * (d->q[1][n] + th * (d->q[2][n] + th * d->q[3][n])));
}

/* The quadratures' growth within one step as a polynomial in phi = (t - t0) / (t1 - t0): their
 * derivatives interpolated at the 5 Gauss-Legendre nodes of [t0, t1] and integrated, so the step's
 * total is the 5-point Gauss rule and a sample inside the step costs a polynomial evaluation. */
typedef struct {
    double t0, span, c[PM_NQ > 0 ? PM_NQ : 1][GL_N]; /* Q(t) - Q(t0) = sum_j c[k][j] phi^(j+1) */
    int moving;                                      /* 0: the quadratures do not change in this step */
} QuadPoly;

static void quad_poly(Run *run, const DensePoly *d, int moving, double ta, double tb, QuadPoly *w) {
    double y[PM_NX], P[GL_N][PM_NQ > 0 ? PM_NQ : 1];
    int q, k, j;
    w->t0 = ta;
    w->span = tb - ta;
    w->moving = moving && w->span > 0.0 && PM_NQ > 0;
    memset(w->c, 0, sizeof w->c);
    if (!w->moving) return;
    for (q = 0; q < GL_N; q++) {
        state_at(d, ta + GL_NODE[q] * w->span, y);
        inputs_at(&run->engine, ta + GL_NODE[q] * w->span, 1); /* inputs that follow a signal, there */
        pm_fq(run->engine.mode, y, run->engine.u, run->engine.p, P[q]);
    }
    for (k = 0; k < PM_NQ; k++)
        for (j = 0; j < GL_N; j++) {
            double acc = 0.0;
            for (q = 0; q < GL_N; q++) acc += P[q][k] * run->gauss[q][j];
            w->c[k][j] = w->span * acc;
        }
}

static void quad_at(const QuadPoly *w, double t, const double *base, double *quad) {
    double phi = w->span > 0.0 ? (t - w->t0) / w->span : 0.0;
    int k, j;
    if (!w->moving) { /* + 0.0 as the polynomial's sum gives */
        for (k = 0; k < PM_NQ; k++) quad[k] = base[k] + 0.0;
        return;
    }
    for (k = 0; k < PM_NQ; k++) {
        double acc = 0.0;
        for (j = GL_N - 1; j >= 0; j--) acc = (acc + w->c[k][j]) * phi;
        quad[k] = base[k] + acc;
    }
}

static double sample_time(const Run *run, int64_t k) {
    /* numpy.linspace(0, T, n): k * (T / (n - 1)), the last one exactly T */
    return k == run->n_samples - 1 ? run->duration_s : (double)k * run->sample_step_s;
}

static void record(Run *run, const double *xd, const double *quad) {
    double *col = run->samples + run->next_sample; /* column-major: state k at k * n */
    double x[PM_NS > 0 ? PM_NS : 1];
    int64_t n = run->n_samples;
    int k;
    all_states(xd, quad, x);
    for (k = 0; k < PM_NS; k++) col[k * n] = x[k];
    run->modes[run->next_sample] = PM_MODE_VALUE[run->engine.mode];
    run->next_sample++;
}

/* Samples per block of record_step. */
#define PAM_SAMPLE_BLOCK 64

/* The samples first..end-1, inside one step: its dense output d and quadrature growth w, from the
 * quadratures run->quad at its start.  A block of samples at a time, state by state, so that each
 * state's column is written in one contiguous run; each value is state_at's and quad_at's, the same
 * operations in the same order. */
static void record_step(Run *run, const DensePoly *d, const QuadPoly *w, int64_t first, int64_t end) {
    double th[PAM_SAMPLE_BLOCK], phi[PAM_SAMPLE_BLOCK];
    const int32_t mode = PM_MODE_VALUE[run->engine.mode];
    int64_t n = run->n_samples, j0;
    int i, k, m, j;
    for (j0 = first; j0 < end; j0 += PAM_SAMPLE_BLOCK) {
        m = end - j0 < PAM_SAMPLE_BLOCK ? (int)(end - j0) : PAM_SAMPLE_BLOCK;
        for (i = 0; i < m; i++) {
            double t = sample_time(run, j0 + i);
            th[i] = d->h > 0.0 ? (t - d->t0) / d->h : 0.0;
            phi[i] = w->span > 0.0 ? (t - w->t0) / w->span : 0.0;
        }
        for (k = 0; k < PM_NX; k++) {
            double *col = run->samples + (int64_t)PM_DYNAMIC[k] * n + j0;
            const double y0 = d->y0[k], q0 = d->q[0][k], q1 = d->q[1][k], q2 = d->q[2][k], q3 = d->q[3][k];
            for (i = 0; i < m; i++) col[i] = y0 + th[i] * (q0 + th[i] * (q1 + th[i] * (q2 + th[i] * q3)));
        }
        for (k = 0; k < PM_NQ; k++) {
            double *col = run->samples + (int64_t)PM_QUADRATURE[k] * n + j0;
            const double base = run->quad[k];
            for (i = 0; i < m; i++) {
                double acc = 0.0;
                if (!w->moving) { /* + 0.0 as the polynomial's sum gives */
                    col[i] = base + 0.0;
                    continue;
                }
                for (j = GL_N - 1; j >= 0; j--) acc = (acc + w->c[k][j]) * phi[i];
                col[i] = base + acc;
            }
        }
        for (i = 0; i < m; i++) run->modes[j0 + i] = mode;
    }
    run->next_sample = end;
}

/* The samples inside an accepted step come from its dense output, as solve_ivp's t_eval. */
static void on_step(void *env, double t0, double t1, double h, const double *y0, const PamStages *stages) {
    Run *run = (Run *)env;
    DensePoly d;
    QuadPoly w;
    double y[PM_NX];
    int64_t end = run->next_sample;
    int moving = stages != NULL && !PM_MODE_QUAD_ZERO[run->engine.mode];
    dense_poly(&d, stages, y0, t0, h);
    quad_poly(run, &d, moving, t0, t1, &w);
    while (end < run->n_samples && sample_time(run, end) <= t1) end++;
    record_step(run, &d, &w, run->next_sample, end);
    quad_at(&w, t1, run->quad, run->quad);
    state_at(&d, t1, y);
    inputs_at(&run->engine, t1, 1);
    note_extremes(run, run->engine.mode, y, run->quad);
}

static void on_event(void *env, double t, int from, int to, unsigned fired, const double *x_before,
                     const double *x_after) {
    Run *run = (Run *)env;
    note_extremes(run, from, x_before, run->quad);
    note_extremes(run, to, x_after, run->quad);
    if (run->n_events < run->capacity) {
        double *e = run->events + PAM_ENGINE_NEV * run->n_events;
        e[0] = t;
        e[1] = PM_MODE_VALUE[from];
        e[2] = PM_MODE_VALUE[to];
        e[3] = (double)fired;
        outputs(run, from, x_before, run->quad, e + 4);
        outputs(run, to, x_after, run->quad, e + 4 + PM_NY);
    }
    run->n_events++;
}

static int finite_all(const double *v, int n) {
    int k;
    for (k = 0; k < n; k++)
        if (!isfinite(v[k])) return 0;
    return 1;
}

static int set_inputs(Run *run, const double *u) {
    int k;
    for (k = 0; k < PM_NU; k++)
        if (!isfinite(u[k])) {
            snprintf(run->message, PAM_ENGINE_MSG, "%s = %g: must be a finite number", PM_INPUTS_NAMES[k], u[k]);
            return -1;
        }
    memcpy(run->engine.u, u, sizeof run->engine.u);
    return 0;
}

/* The inputs of the current segment at t_s: each in closed form, so the integrator sees them exactly. */
static void segment_inputs_at(void *env, double t_s, int left, double *u) {
    const Run *run = (const Run *)env;
    double dt = t_s - run->seg_t0;
    int k;
    (void)left; /* continuous inside a segment: its ends are the segments' boundaries */
    for (k = 0; k < PM_NU; k++) {
        const double *d = run->seg_du + 3 * k;
        u[k] = run->seg_u0[k] + d[0] * dt + (d[2] > 0.0 ? d[1] * expm1(-dt / d[2]) : 0.0);
    }
}

/* A segment ends where do_step is asked to stop: no breakpoint inside it. */
static double segment_next_breakpoint(void *env, double t_s) {
    (void)env;
    (void)t_s;
    return HUGE_VAL;
}

static int segment_constant(void *env, double t_s) {
    const Run *run = (const Run *)env;
    int k;
    (void)t_s;
    for (k = 0; k < PM_NU; k++)
        if (run->seg_du[3 * k] != 0.0 || (run->seg_du[3 * k + 2] > 0.0 && run->seg_du[3 * k + 1] != 0.0)) return 0;
    return 1;
}

/* The segment from seg_t (its start) with inputs seg_u there and their change seg_du (NULL: held). */
static int enter_segment(Run *run, double seg_t, const double *seg_u, const double *seg_du) {
    PamEngine *e = &run->engine;
    int k;
    if (set_inputs(run, seg_u)) return -1;
    run->seg_t0 = seg_t;
    run->seg_u0 = seg_u;
    run->seg_du = seg_du;
    for (k = 0; seg_du && k < 3 * PM_NU; k++)
        if (!isfinite(seg_du[k]) || (k % 3 == 2 && seg_du[k] < 0.0)) {
            snprintf(run->message, PAM_ENGINE_MSG, "%s: a segment's change is not finite", PM_INPUTS_NAMES[k / 3]);
            return -1;
        }
    /* A segment whose inputs do not change is held: nothing to evaluate at every stage. */
    e->inputs = seg_du && !segment_constant(run, seg_t) ? &run->inputs : NULL;
    return 0;
}

static int run_case(const PamEngineBatch *b, int64_t i) {
    Run run;
    PamEngine *e = &run.engine;
    const double *seg_t = b->segment_t_s + b->segment_offset[i];
    const double *seg_u = b->segment_u + PM_NU * b->segment_offset[i];
    const double *seg_du = b->segment_du ? b->segment_du + 3 * PM_NU * b->segment_offset[i] : NULL;
    double quad0[PM_NQ > 0 ? PM_NQ : 1];
    int64_t n_seg = b->n_segments[i], j;
    int k;

    memset(&run, 0, sizeof run);
    pam_engine_reset(e);
    gauss_primitives(run.gauss);
    run.message = b->messages + PAM_ENGINE_MSG * i;
    run.message[0] = '\0';
    run.events = b->events + PAM_ENGINE_NEV * b->event_offset[i];
    run.capacity = b->event_capacity[i];
    run.samples = b->samples + PM_NS * b->sample_offset[i];
    run.modes = b->modes + b->sample_offset[i];
    run.n_samples = b->n_samples[i];
    run.duration_s = b->duration_s[i];
    run.sample_step_s = run.n_samples > 1 ? run.duration_s / (double)(run.n_samples - 1) : 0.0;
    run.y_max = b->extremes + 2 * PM_NY * i;
    run.y_min = run.y_max + PM_NY;
    for (k = 0; k < PM_NY; k++) {
        run.y_max[k] = -INFINITY;
        run.y_min[k] = INFINITY;
    }
    memcpy(e->p, b->params + PM_NP * i, sizeof e->p);
    if (!finite_all(e->p, PM_NP)) {
        for (k = 0; k < PM_NP && isfinite(e->p[k]); k++) continue;
        snprintf(run.message, PAM_ENGINE_MSG, "%s = %g: must be a finite number", PM_PARAMETERS_NAMES[k], e->p[k]);
        return ENGINE_BAD_INPUT;
    }
    e->rtol = b->rtol[i];
    e->max_step_s = b->max_step_s[i];
    e->max_steps = (long)b->max_steps[i];
    e->stiff_switch = b->stiff_switch[i] != 0;
    e->log = keep_first_error;
    e->log_env = &run;
    run.inputs.at = segment_inputs_at;
    run.inputs.next_breakpoint = segment_next_breakpoint;
    run.inputs.constant_after = segment_constant;
    run.inputs.env = &run;
    if (enter_segment(&run, seg_t[0], seg_u, seg_du)) return ENGINE_BAD_INPUT;
    pam_engine_initialize(e);
    for (k = 0; k < PM_NQ; k++) quad0[k] = e->q_start[PM_QUADRATURE[k]];
    memcpy(run.quad, quad0, sizeof run.quad);
    e->on_event = on_event;
    e->event_env = &run;
    e->on_step = on_step;
    e->step_env = &run;
    note_extremes(&run, e->mode, e->x, run.quad);
    record(&run, e->x, run.quad);
    for (j = 1; j <= n_seg; j++) {
        double t_next = j < n_seg ? seg_t[j] : run.duration_s;
        if (pam_engine_do_step(e, t_next)) return ENGINE_SOLVER_FAILED;
        if (run.n_events > run.capacity) return ENGINE_EVENTS_FULL;
        /* a remainder below the time resolution is not stepped: its samples are the end state */
        while (run.next_sample < run.n_samples && sample_time(&run, run.next_sample) <= t_next)
            record(&run, e->x, run.quad);
        if (j < n_seg) {
            /* the next segment sees the inputs' new values; a held model is re-checked */
            if (enter_segment(&run, seg_t[j], seg_u + PM_NU * j, seg_du ? seg_du + 3 * PM_NU * j : NULL))
                return ENGINE_BAD_INPUT;
            e->inputs_changed = 1;
        }
    }
    b->stats[4 * i] = e->n_rhs;
    b->stats[4 * i + 1] = e->n_steps;
    b->stats[4 * i + 2] = n_seg + run.n_events;
    b->stats[4 * i + 3] = e->n_jacobians;
    b->n_events[i] = run.n_events;
    return ENGINE_OK;
}

PAM_EXPORT int64_t pam_engine_run_batch(const PamEngineBatch *b) {
    int64_t i, failed = 0;
    for (i = 0; i < b->n_cases; i++) {
        b->n_events[i] = 0;
        b->stats[4 * i] = b->stats[4 * i + 1] = b->stats[4 * i + 2] = b->stats[4 * i + 3] = 0;
        b->status[i] = run_case(b, i);
        failed += b->status[i] != ENGINE_OK;
    }
    return failed;
}

/* Sizes the Python side checks against its own layout before the first call. */
PAM_EXPORT int64_t pam_engine_layout(int64_t which) {
    const int64_t sizes[] = {PM_NX, PM_NQ, PM_NU, PM_NP, PM_NY, PM_NZ, PM_NMODES, PM_NS, PAM_ENGINE_NEV,
                             PAM_ENGINE_MSG, (int64_t)sizeof(PamEngineBatch)};
    return which >= 0 && which < (int64_t)(sizeof sizes / sizeof sizes[0]) ? sizes[which] : -1;
}

#include "pam_engine_session.c"
