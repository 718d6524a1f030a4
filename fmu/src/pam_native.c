/* pamsim native backend; see pam_native.h.
 *
 * The library is a unity build of the core: including pam_core.c here gives this file the core's
 * element functions (static there, and hidden from the FMU's exports) without widening the FMU's
 * interface or keeping a second copy of any equation.  Only the PAM_EXPORT functions leave it.
 */
#include "pam_core.c"
#include "pam_fmu_common.c"

#include "pam_native.h"
#include "pam_gauss.h"

/* Order of segment_u, as pamsim.native.library.INPUTS. */
static const int INPUT_R[PAM_NATIVE_NU] = {R_valve_command, R_supply_pressure_gauge_Pa,
                                           R_prescribed_pressure_gauge_Pa, R_load_mass_kg, R_external_force_N};

enum { W_MUSCLE, E_FRICTION, E_DAMPING, W_EXTERNAL, N_WORK };

typedef struct {
    PamCore core;
    char *message;
    double *events, *rows;
    int32_t *modes;
    int64_t capacity, n_events, n_samples, next_sample;
    double sample_step_s, duration_s;
    double work[N_WORK], impacts_J;
    double gauss[GL_N][GL_N];
    double x_max, x_min, p_max; /* over every step end and event (simulator: Result.peaks) */
    PamTable table;             /* the case's static force table, if it has one */
    double seg_t0;              /* the segment being integrated: its start, inputs there, their change */
    const double *seg_u0, *seg_du;
} Run;

/* The inputs of the current segment at t_s, in closed form (PamBatch.segment_du). */
static void segment_inputs_at(void *env, PamCore *c, double t_s) {
    const Run *run = (const Run *)env;
    double dt = t_s - run->seg_t0;
    int k;
    for (k = 0; k < PAM_NATIVE_NU; k++) {
        const double *d = run->seg_du + 3 * k;
        c->r[INPUT_R[k]] = run->seg_u0[k] + d[0] * dt + (d[2] > 0.0 ? d[1] * expm1(-dt / d[2]) : 0.0);
    }
}

static int segment_constant(void *env) {
    const Run *run = (const Run *)env;
    int k;
    for (k = 0; k < PAM_NATIVE_NU; k++)
        if (run->seg_du[3 * k] != 0.0 || (run->seg_du[3 * k + 2] > 0.0 && run->seg_du[3 * k + 1] != 0.0)) return 0;
    return 1;
}

/* Inputs that follow their segment's closed form, at t_s; held ones stay as they are. */
static void inputs_now(Run *run, double t_s) {
    if (run->core.inputs_fn) run->core.inputs_fn(run, &run->core, t_s);
}

static void note_peaks(Run *run, const double *y) {
    double p = pressure_gauge_Pa(&run->core, y);
    if (y[X] > run->x_max) run->x_max = y[X];
    if (y[X] < run->x_min) run->x_min = y[X];
    if (p > run->p_max) run->p_max = p;
}

static void keep_first_error(void *env, int level, const char *message) {
    Run *run = (Run *)env;
    if (level == PAM_LOG_ERROR && run->message[0] == '\0') snprintf(run->message, PAM_NATIVE_MSG, "%s", message);
}

/* MuscleModel.slip_rhs: the powers whose integrals are the work states (zero while held, v = 0). */
static void powers_W(const PamCore *c, const double *y, double *P) {
    double p = pressure_gauge_Pa(c, y), v = y[V];
    P[W_MUSCLE] = static_force_N(c, y[X], p) * v;
    P[E_FRICTION] = coulomb_level_N(c, y[X], p) * fabs(v);
    P[E_DAMPING] = damping_force_N(c, v) * v;
    P[W_EXTERNAL] = c->r[R_external_force_N] * v;
}

/* One step's dense output (Shampine's 4th-order extension, DP_P of pam_core.c) as a polynomial,
 * y(t0 + th h) = y0 + sum_j q[j] th^(j+1), factored once per step rather than once per sample:
 * sampling at 1 kHz evaluates it several times per step.  A NULL stages (a held load at rest) is
 * the constant y0. */
typedef struct {
    double t0, h, y0[PAM_NX], q[4][PAM_NX];
} DensePoly;

static void dense_poly(DensePoly *d, const DpStages *s, const double *y0, double t0, double h) {
    int n, j, st;
    d->t0 = t0;
    d->h = h;
    memcpy(d->y0, y0, sizeof d->y0);
    for (j = 0; j < 4; j++)
        for (n = 0; n < PAM_NX; n++) {
            double acc = 0.0;
            if (s)
                for (st = 0; st < 7; st++) acc += s->k[st][n] * DP_P[st][j];
            d->q[j][n] = h * acc;
        }
}

static void state_at(const DensePoly *d, double t, double *y) {
    double th = d->h > 0.0 ? (t - d->t0) / d->h : 0.0;
    int n;
    for (n = 0; n < PAM_NX; n++) y[n] = d->y0[n] + th * (d->q[0][n] + th * (d->q[1][n] + th * (d->q[2][n] + th * d->q[3][n])));
}

/* The work done within one step as a polynomial in phi = (t - t0) / (t1 - t0): the powers are
 * interpolated at the 5 Gauss-Legendre nodes of [t0, t1] and integrated, so the step's total is the
 * 5-point Gauss rule (exact for polynomials of degree 9, its error below the dense output's own) and
 * a sample inside the step costs a polynomial evaluation rather than a quadrature of its own: the
 * powers are evaluated 5 times a step instead of 3 times a sample. */
typedef struct {
    double t0, span, c[N_WORK][GL_N]; /* W(t) - W(t0) = sum_j c[k][j] phi^(j+1) */
    int moving;                       /* 0: no work in this step (c is zero) */
} WorkPoly;

static void work_poly(Run *run, const DensePoly *d, double A[GL_N][GL_N], int moving, double ta, double tb,
                      WorkPoly *w) {
    double y[PAM_NX], P[GL_N][N_WORK];
    int q, k, j;
    w->t0 = ta;
    w->span = tb - ta;
    w->moving = moving && w->span > 0.0;
    memset(w->c, 0, sizeof w->c);
    if (!w->moving) return; /* a held load does no work */
    for (q = 0; q < GL_N; q++) {
        state_at(d, ta + GL_NODE[q] * w->span, y);
        inputs_now(run, ta + GL_NODE[q] * w->span);
        powers_W(&run->core, y, P[q]);
    }
    for (k = 0; k < N_WORK; k++)
        for (j = 0; j < GL_N; j++) {
            double acc = 0.0;
            for (q = 0; q < GL_N; q++) acc += P[q][k] * A[q][j];
            w->c[k][j] = w->span * acc;
        }
}

static void work_at(const WorkPoly *w, double t, const double *base, double *work) {
    double phi = w->span > 0.0 ? (t - w->t0) / w->span : 0.0;
    int k, j;
    if (!w->moving) { /* most samples of a run: the load is held; + 0.0 as the polynomial's sum gives */
        for (k = 0; k < N_WORK; k++) work[k] = base[k] + 0.0;
        return;
    }
    for (k = 0; k < N_WORK; k++) {
        double acc = 0.0;
        for (j = GL_N - 1; j >= 0; j--) acc = (acc + w->c[k][j]) * phi;
        work[k] = base[k] + acc;
    }
}

static double sample_time(const Run *run, int64_t k) {
    /* numpy.linspace(0, T, n): k * (T / (n - 1)), the last one exactly T */
    return k == run->n_samples - 1 ? run->duration_s : (double)k * run->sample_step_s;
}

static void record(Run *run, const double *y, const double *work) {
    double *col = run->rows + run->next_sample; /* the case's block is column-major: column q at q * n */
    int64_t n = run->n_samples;
    int k;
    for (k = 0; k < PAM_NX; k++) col[k * n] = y[k];
    for (k = 0; k < N_WORK; k++) col[(PAM_NX + k) * n] = work[k];
    col[(PAM_NX + N_WORK) * n] = run->impacts_J;
    run->modes[run->next_sample] = run->core.mode;
    run->next_sample++;
}

/* The samples inside an accepted step come from its dense output, as solve_ivp's t_eval; the work
 * integrals from the step's work polynomial. */
static void on_step(void *env, double t0, double t1, double h, const double *y0, const void *stages) {
    Run *run = (Run *)env;
    DensePoly d;
    WorkPoly w;
    double y[PAM_NX], work[N_WORK];
    int moving = stages != NULL && sliding(run->core.mode);
    dense_poly(&d, (const DpStages *)stages, y0, t0, h);
    work_poly(run, &d, run->gauss, moving, t0, t1, &w);
    while (run->next_sample < run->n_samples && sample_time(run, run->next_sample) <= t1) {
        double t = sample_time(run, run->next_sample);
        state_at(&d, t, y);
        work_at(&w, t, run->work, work);
        record(run, y, work);
    }
    work_at(&w, t1, run->work, run->work);
    state_at(&d, t1, y);
    inputs_now(run, t1);
    note_peaks(run, y);
}

static int event_kind(int from, int to, const PamCore *c, const double *y_after) {
    if (from == PAM_SLIP_UP || from == PAM_SLIP_DOWN) {
        if (from == PAM_SLIP_UP && y_after[X] == c->x_high_m) return PAM_EV_STOP_HIGH;
        if (from == PAM_SLIP_DOWN && y_after[X] == c->x_low_m) return PAM_EV_STOP_LOW;
        return PAM_EV_VELOCITY_ZERO;
    }
    return to == PAM_SLIP_UP ? PAM_EV_RELEASE_UP : PAM_EV_RELEASE_DOWN;
}

/* simulator._transition's bookkeeping: the event, the kinetic energy the jump removed, the work nodes. */
static void on_event(void *env, double t, int from, int to, const double *y_before, const double *y_after) {
    Run *run = (Run *)env;
    double m = run->core.r[R_load_mass_kg], loss;
    loss = 0.5 * m * (y_before[V] * y_before[V] - y_after[V] * y_after[V]);
    run->impacts_J += loss;
    note_peaks(run, y_before);
    note_peaks(run, y_after);
    if (run->n_events < run->capacity) {
        double *e = run->events + PAM_NATIVE_NEV * run->n_events;
        e[0] = t;
        e[1] = event_kind(from, to, &run->core, y_after);
        e[2] = from;
        e[3] = to;
        e[4] = y_after[X];
        e[5] = loss;
    }
    run->n_events++;
}

static const unsigned INPUT_VR[PAM_NATIVE_NU] = {VR_valve_command, VR_supply_pressure_gauge_Pa,
                                                 VR_prescribed_pressure_gauge_Pa, VR_load_mass_kg, VR_external_force_N};

/* The FMU's input checks (pam_check_value), then the values; -1 (logged) if one is refused. */
static int set_inputs(PamCore *c, const double *u) {
    int k;
    for (k = 0; k < PAM_NATIVE_NU; k++)
        if (pam_check_value(c, INPUT_VR[k], u[k])) return -1;
    for (k = 0; k < PAM_NATIVE_NU; k++) c->r[INPUT_R[k]] = u[k];
    return 0;
}

/* The segment from seg_t with inputs seg_u there and their change seg_du (NULL: held); -1 if refused. */
static int enter_segment(Run *run, double seg_t, const double *seg_u, const double *seg_du) {
    int k;
    if (set_inputs(&run->core, seg_u)) return -1;
    for (k = 0; seg_du && k < 3 * PAM_NATIVE_NU; k++)
        if (!isfinite(seg_du[k]) || (k % 3 == 2 && seg_du[k] < 0.0)) {
            snprintf(run->message, PAM_NATIVE_MSG, "a segment's change of input %d is not finite", k / 3);
            return -1;
        }
    run->seg_t0 = seg_t;
    run->seg_u0 = seg_u;
    run->seg_du = seg_du;
    run->core.inputs_fn = seg_du ? segment_inputs_at : NULL;
    run->core.inputs_constant_fn = segment_constant;
    run->core.inputs_env = run;
    return 0;
}

static int run_case(const PamBatch *b, int64_t i) {
    Run run;
    PamCore *c = &run.core;
    const double *seg_t = b->segment_t_s + b->segment_offset[i];
    const double *seg_u = b->segment_u + PAM_NATIVE_NU * b->segment_offset[i];
    const double *seg_du = b->segment_du ? b->segment_du + 3 * PAM_NATIVE_NU * b->segment_offset[i] : NULL;
    double y[PAM_NX];
    int64_t n_seg = b->n_segments[i], j;

    memset(&run, 0, sizeof run);
    gauss_primitives(run.gauss);
    run.message = b->messages + PAM_NATIVE_MSG * i;
    run.message[0] = '\0';
    run.events = b->events + PAM_NATIVE_NEV * b->event_offset[i];
    run.capacity = b->event_capacity[i];
    run.rows = b->samples + PAM_NATIVE_NOUT * b->sample_offset[i];
    run.modes = b->modes + b->sample_offset[i];
    run.n_samples = b->n_samples[i];
    run.duration_s = b->duration_s[i];
    run.sample_step_s = run.n_samples > 1 ? run.duration_s / (double)(run.n_samples - 1) : 0.0;
    pam_reset(c);
    memcpy(c->r, b->reals + PAM_NR * i, sizeof c->r);
    memcpy(c->i, b->ints + PAM_NI * i, sizeof c->i);
    c->log = keep_first_error;
    c->log_env = &run;
    if (b->table_index[i] >= 0) {
        const double *g = b->table_grid + 6 * b->table_index[i];
        run.table.nx = (int)g[0];
        run.table.np = (int)g[1];
        run.table.x0 = g[2];
        run.table.dx = g[3];
        run.table.p0 = g[4];
        run.table.dp = g[5];
        run.table.nodes = (const double(*)[4])(b->table_nodes + 4 * b->table_offset[b->table_index[i]]);
        c->table = &run.table;
    }
    if (enter_segment(&run, seg_t[0], seg_u, seg_du) || pam_check_parameters(c)) return PAM_BAD_INPUT;
    pam_initialize(c);
    c->on_event = on_event;
    c->event_env = &run;
    c->on_step = on_step;
    c->step_env = &run;
    get_states(c, y);
    run.x_max = run.x_min = y[X];
    run.p_max = pressure_gauge_Pa(c, y);
    record(&run, y, run.work);
    for (j = 1; j <= n_seg; j++) {
        double t_next = j < n_seg ? seg_t[j] : run.duration_s;
        if (pam_do_step(c, t_next)) return PAM_SOLVER_FAILED;
        if (run.n_events > run.capacity) return PAM_EVENTS_FULL;
        /* a remainder below the time resolution is not stepped: its samples are the end state */
        get_states(c, y);
        while (run.next_sample < run.n_samples && sample_time(&run, run.next_sample) <= t_next)
            record(&run, y, run.work);
        if (j < n_seg) {
            /* simulator: the next segment sees the inputs' new values; a held load is re-checked */
            if (enter_segment(&run, seg_t[j], seg_u + PAM_NATIVE_NU * j, seg_du ? seg_du + 3 * PAM_NATIVE_NU * j : NULL))
                return PAM_BAD_INPUT;
            c->inputs_changed = 1;
        }
    }
    b->stats[3 * i] = c->n_rhs;
    b->stats[3 * i + 1] = c->n_steps;
    b->stats[3 * i + 2] = n_seg + run.n_events;
    b->n_events[i] = run.n_events;
    b->peaks[3 * i] = run.x_max;
    b->peaks[3 * i + 1] = run.x_min;
    b->peaks[3 * i + 2] = run.p_max;
    return PAM_OK;
}

PAM_EXPORT int64_t pam_native_run_batch(const PamBatch *b) {
    int64_t i, failed = 0;
    for (i = 0; i < b->n_cases; i++) {
        b->n_events[i] = 0;
        b->stats[3 * i] = b->stats[3 * i + 1] = b->stats[3 * i + 2] = 0;
        b->status[i] = run_case(b, i);
        failed += b->status[i] != PAM_OK;
    }
    return failed;
}

PAM_EXPORT void pam_native_evaluate(int64_t n, const double *reals, const int32_t *ints, const double *states,
                                    const int32_t *modes, double *out) {
    PamCore c;
    int64_t i;
    memset(&c, 0, sizeof c);
    for (i = 0; i < n; i++) {
        const double *y = states + PAM_NX * i;
        double *q = out + PAM_NATIVE_NQ * i, dy[PAM_NX], z[PAM_NZ], p;
        int mode = modes[i];
        memcpy(c.r, reals + PAM_NR * i, sizeof c.r);
        memcpy(c.i, ints + PAM_NI * i, sizeof c.i);
        braid_geometry(c.r, &c.braid_b_m, &c.braid_turns);
        c.x_low_m = 0.0;
        c.x_high_m = upper_stop_m(c.r);
        p = pressure_gauge_Pa(&c, y);
        q[Q_PRESSURE_GAUGE] = p;
        q[Q_STATIC_FORCE] = static_force_N(&c, y[X], p);
        q[Q_COULOMB_LEVEL] = coulomb_level_N(&c, y[X], p);
        q[Q_DAMPING_FORCE] = damping_force_N(&c, y[V]);
        chamber_derivatives(&c, y, y[V], &q[Q_PRESSURE_RATE], &q[Q_VALVE_FLOW]);
        rhs(&c, mode, y, dy);
        q[Q_RHS_X] = dy[X];
        q[Q_RHS_V] = dy[V];
        q[Q_RHS_P] = dy[P];
        q[Q_RHS_M] = dy[M];
        indicators(&c, mode, y, z);
        q[Q_INDICATOR_1] = z[0];
        q[Q_INDICATOR_2] = z[1];
        rest_forces(&c, y, &q[Q_NET_FORCE], &q[Q_LEVEL_AT_REST]);
        q[Q_REST_MODE] = rest_mode(&c, y, mode == PAM_SLIP_UP || mode == PAM_SLIP_DOWN ? PAM_STICK : mode);
        q[Q_VOLUME] = volume_m3(&c, y[X]);
        q[Q_UPPER_STOP] = c.x_high_m;
    }
}

PAM_EXPORT int64_t pam_native_layout(int64_t which) {
    const int64_t sizes[] = {PAM_NR, PAM_NI, PAM_NATIVE_NU, PAM_NATIVE_NOUT, PAM_NATIVE_NEV, PAM_NATIVE_NQ,
                             PAM_NATIVE_MSG, (int64_t)sizeof(PamBatch), PAM_NX};
    return which >= 0 && which < (int64_t)(sizeof sizes / sizeof sizes[0]) ? sizes[which] : -1;
}
