/* pamsim generic engine, stepped: one run advanced by its caller, a step at a time, with the inputs
 * held over each step (a controller's sample, a reinforcement-learning environment's action).
 *
 * Included at the end of pam_engine_batch.c, so that a session is a batch case without samples: the
 * same Run, the same step and event hooks (the work integrals by Gauss quadrature of each step's
 * dense output, the extremes of every output), and the same engine calls in the same order.  A
 * session advanced from t_k to t_(k+1) with inputs u_k therefore does what a batch case with input
 * segments starting at every t_k does, operation for operation.
 */

#include <stdlib.h>

typedef struct {
    Run run;
    double y_max[PM_NY > 0 ? PM_NY : 1], y_min[PM_NY > 0 ? PM_NY : 1];
    char message[PAM_ENGINE_MSG];
    /* 0 until the first advance: a run starts from the state and mode its first inputs decide, as a
     * batch case starts from its first segment's inputs. */
    int started;
    int ready; /* a reset succeeded and no advance has failed since */
} PamEngineSession;

PAM_EXPORT PamEngineSession *pam_engine_session_new(void) {
    PamEngineSession *s = (PamEngineSession *)calloc(1, sizeof *s);
    if (s) s->run.message = s->message; /* errors before the first reset have somewhere to go */
    return s;
}

PAM_EXPORT void pam_engine_session_free(PamEngineSession *s) { free(s); }

static void session_start(PamEngineSession *s) {
    PamEngine *e = &s->run.engine;
    int k;
    pam_engine_initialize(e);
    for (k = 0; k < PM_NQ; k++) s->run.quad[k] = e->q_start[PM_QUADRATURE[k]];
    for (k = 0; k < PM_NY; k++) {
        s->y_max[k] = -INFINITY;
        s->y_min[k] = INFINITY;
    }
    note_extremes(&s->run, e->mode, e->x, s->run.quad);
}

/* A new run at t = 0 with the parameters `params` (PM_NP), the inputs `u` (PM_NU) and the solver
 * settings; `max_steps` bounds the internal steps of one advance, `stiff_switch` is PamEngine's.
 * Returns an EngineStatus. */
PAM_EXPORT int32_t pam_engine_session_reset(PamEngineSession *s, const double *params, const double *u, double rtol,
                                            double max_step_s, int64_t max_steps, int32_t stiff_switch) {
    Run *run = &s->run;
    PamEngine *e = &run->engine;
    int k;
    memset(run, 0, sizeof *run);
    s->started = s->ready = 0;
    pam_engine_reset(e);
    gauss_primitives(run->gauss);
    run->message = s->message;
    run->message[0] = '\0';
    run->y_max = s->y_max;
    run->y_min = s->y_min;
    memcpy(e->p, params, sizeof e->p);
    if (!finite_all(e->p, PM_NP)) {
        for (k = 0; k < PM_NP && isfinite(e->p[k]); k++) continue;
        snprintf(run->message, PAM_ENGINE_MSG, "%s = %g: must be a finite number", PM_PARAMETERS_NAMES[k], e->p[k]);
        return ENGINE_BAD_INPUT;
    }
    if (!(rtol > 0.0) || !(max_step_s > 0.0) || max_steps < 1) {
        snprintf(run->message, PAM_ENGINE_MSG, "rtol = %g, max_step_s = %g, max_steps = %lld: must be positive", rtol,
                 max_step_s, (long long)max_steps);
        return ENGINE_BAD_INPUT;
    }
    e->rtol = rtol;
    e->max_step_s = max_step_s;
    e->max_steps = (long)max_steps;
    e->stiff_switch = stiff_switch != 0;
    e->log = keep_first_error;
    e->log_env = run;
    if (set_inputs(run, u)) return ENGINE_BAD_INPUT;
    session_start(s);
    e->on_event = on_event;
    e->event_env = run;
    e->on_step = on_step;
    e->step_env = run;
    s->ready = 1;
    return ENGINE_OK;
}

/* Hold the inputs `u` from the session's time to t_end_s and integrate there.  Bad inputs or a
 * t_end_s not after the session's time change nothing (ENGINE_BAD_INPUT); a solver failure leaves the
 * session at the last instant reached, and it must be reset before it advances again. */
PAM_EXPORT int32_t pam_engine_session_advance(PamEngineSession *s, const double *u, double t_end_s) {
    Run *run = &s->run;
    PamEngine *e = &run->engine;
    double saved[PM_NU > 0 ? PM_NU : 1];
    if (!s->ready) {
        snprintf(run->message, PAM_ENGINE_MSG, "the session must be reset first");
        return ENGINE_BAD_INPUT;
    }
    run->message[0] = '\0';
    if (!(t_end_s > e->time_s) || !isfinite(t_end_s)) {
        snprintf(run->message, PAM_ENGINE_MSG, "t_end_s = %.17g: must be a finite time after %.17g s", t_end_s,
                 e->time_s);
        return ENGINE_BAD_INPUT;
    }
    memcpy(saved, e->u, sizeof saved);
    if (set_inputs(run, u)) {
        memcpy(e->u, saved, sizeof saved);
        return ENGINE_BAD_INPUT;
    }
    if (!s->started) {
        session_start(s);
        s->started = 1;
    } else {
        e->inputs_changed = 1; /* as at a batch case's segment boundary: a held model is re-checked */
    }
    if (pam_engine_do_step(e, t_end_s)) {
        s->ready = 0;
        return ENGINE_SOLVER_FAILED;
    }
    return ENGINE_OK;
}

/* Every state (PM_NS, quadratures included) into x and every output (PM_NY, in the current mode) into y,
 * either may be NULL; info (may be NULL) gets the time [s], the mode's value, the right-hand-side
 * evaluations, the accepted steps and the events since the reset.  Returns the mode's value. */
PAM_EXPORT int32_t pam_engine_session_read(const PamEngineSession *s, double *x, double *y, double *info) {
    const Run *run = &s->run;
    const PamEngine *e = &run->engine;
    if (x) all_states(e->x, run->quad, x);
    if (y) outputs(run, e->mode, e->x, run->quad, y);
    if (info) {
        info[0] = e->time_s;
        info[1] = PM_MODE_VALUE[e->mode];
        info[2] = (double)e->n_rhs;
        info[3] = (double)e->n_steps;
        info[4] = (double)run->n_events;
    }
    return PM_MODE_VALUE[e->mode];
}

/* One call per control step: advance, then read (as pam_engine_session_advance and _read). */
PAM_EXPORT int32_t pam_engine_session_step(PamEngineSession *s, const double *u, double t_end_s, double *x,
                                           double *y) {
    int32_t status = pam_engine_session_advance(s, u, t_end_s);
    if (status == ENGINE_OK) pam_engine_session_read(s, x, y, NULL);
    return status;
}

/* The extremes of every output since the reset: the largest values, then the smallest (2 PM_NY). */
PAM_EXPORT void pam_engine_session_extremes(const PamEngineSession *s, double *out) {
    memcpy(out, s->y_max, PM_NY * sizeof(double));
    memcpy(out + PM_NY, s->y_min, PM_NY * sizeof(double));
}

PAM_EXPORT const char *pam_engine_session_message(const PamEngineSession *s) { return s->message; }
