/* What both FMU cores share (see pam_fmu_common.h): logging, the range check of a variable, and the
 * input signals of the scenario an FMU was built from. */
#include "pam_fmu_common.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void pam_logf(PamCore *c, int level, const char *fmt, ...) {
    char buf[512];
    va_list ap;
    if (!c->log) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    c->log(c->log_env, level, buf);
}

/* pamsim.parameters.Parameter.violation: 1 and the reason in `why` if `value` is outside the
 * generated range of `info`, else 0. */
int pam_range_violation(const PamVarInfo *info, double value, char *why, size_t size) {
    int low_bad = info->lower_open ? value <= info->lower : value < info->lower;
    int high_bad = info->upper_open ? value >= info->upper : value > info->upper;
    if (!low_bad && !high_bad) return 0;
    if (isinf(info->upper)) snprintf(why, size, "must be %s %g", info->lower_open ? ">" : ">=", info->lower);
    else if (isinf(info->lower)) snprintf(why, size, "must be %s %g", info->upper_open ? "<" : "<=", info->upper);
    else
        snprintf(why, size, "must lie in %c%g, %g%c", info->lower_open ? '(' : '[', info->lower, info->upper,
                 info->upper_open ? ')' : ']');
    return 1;
}

int pam_check_own_range(PamCore *c, unsigned vr, double value) {
    const PamVarInfo *info;
    char why[160];
    if (vr < 1 || vr > PAM_NVARS) return 0;
    info = &PAM_VARS[vr - 1];
    if (!isfinite(value)) {
        pam_logf(c, PAM_LOG_ERROR, "%s = %g: must be a finite number", info->name, value);
        return -1;
    }
    if (info->causality == PAM_INPUT && pam_range_violation(info, value, why, sizeof why)) {
        pam_logf(c, PAM_LOG_ERROR, "%s = %g: %s", info->name, value, why);
        return -1;
    }
    return 0;
}

int pam_check_parameter_ranges(PamCore *c) {
    int bad = 0, k;
    char why[160];
    for (k = 0; k < PAM_NVARS; k++)
        if (PAM_VARS[k].kind == 'r' && PAM_VARS[k].causality <= PAM_INPUT && !isfinite(c->r[PAM_VARS[k].index])) {
            pam_logf(c, PAM_LOG_ERROR, "invalid parameters: %s is not finite", PAM_VARS[k].name);
            bad = -1;
        }
    if (bad) return -1;
    for (k = 0; k < PAM_NVARS; k++) {
        const PamVarInfo *info = &PAM_VARS[k];
        double value = info->kind == 'r' ? c->r[info->index] : (double)c->i[info->index];
        if (info->causality == PAM_PARAMETER && pam_range_violation(info, value, why, sizeof why)) {
            if (info->kind == 'r') pam_logf(c, PAM_LOG_ERROR, "invalid parameters: %s = %g: %s", info->name, value, why);
            else pam_logf(c, PAM_LOG_ERROR, "invalid parameters: %s = %ld: %s", info->name, (long)c->i[info->index], why);
            bad = -1;
        }
    }
    return bad;
}

/* ------------------------------------------------------------ the scenario's input signals */

static int scheduled(const PamCore *c) {
    return PAM_NSIG > 0 && c->i[I_input_source] == PAM_INPUT_SOURCE_SCENARIO;
}

/* pamsim.fmu.preset.InputSignal: knots interpolated as numpy.interp does and held outside them, a knot
 * time given twice being a step; or a step through a first-order lag (pamsim.signals.FirstOrderLag).
 * Its pieces run between breakpoints.  The piece of t_piece is the one that contains it; where t_piece is a
 * breakpoint, the one that ends there (`left`) or the one that starts there.  It is evaluated at t, its
 * formula continued beyond its ends. */
static double signal_on_piece(const PamSignal *s, double t_piece, int left, double t) {
    int lo = 0, hi = s->n, k;
    if (s->n == 0) {
        if (left ? t_piece <= s->time_s : t_piece < s->time_s) return s->initial;
        return s->final + (s->initial - s->final) * exp(-(t - s->time_s) / s->tau_s);
    }
    while (lo < hi) { /* lo: the knots before t_piece (left) or at or before it (right) */
        int mid = (lo + hi) / 2;
        if (left ? s->t_s[mid] < t_piece : s->t_s[mid] <= t_piece) lo = mid + 1;
        else hi = mid;
    }
    k = lo - 1;
    if (k < 0) return s->value[0];
    if (k == s->n - 1) return s->value[k];
    return (s->value[k + 1] - s->value[k]) / (s->t_s[k + 1] - s->t_s[k]) * (t - s->t_s[k]) + s->value[k];
}

/* `left`: the value from the left of t, which the integrator takes up to a breakpoint. */
static double signal_value(const PamSignal *s, double t, int left) { return signal_on_piece(s, t, left, t); }

void pam_inputs_on_piece(PamCore *c, double t_piece_s, double t_s) {
    int k;
    if (!scheduled(c)) return;
    for (k = 0; k < PAM_NSIG; k++) c->r[PAM_SIGNALS[k].r] = signal_on_piece(&PAM_SIGNALS[k], t_piece_s, 0, t_s);
}

/* The signals at t_s, but for the inputs in `keep` (bit k: signal k). */
void pam_apply_signals(PamCore *c, double t_s, int left, unsigned keep) {
    int k;
    if (!scheduled(c)) return;
    for (k = 0; k < PAM_NSIG; k++)
        if (!(keep >> k & 1u)) c->r[PAM_SIGNALS[k].r] = signal_value(&PAM_SIGNALS[k], t_s, left);
}

void pam_inputs_at(PamCore *c, double t_s, int left) { pam_apply_signals(c, t_s, left, 0u); }

void pam_mark_input_set(PamCore *c, unsigned vr) {
    int k;
    for (k = 0; k < PAM_NSIG; k++)
        if (PAM_SIGNALS[k].vr == vr) c->inputs_set |= 1u << k;
}

int pam_input_scheduled(const PamCore *c, unsigned vr, double *value) {
    int k;
    if (!scheduled(c)) return 0;
    for (k = 0; k < PAM_NSIG; k++)
        if (PAM_SIGNALS[k].vr == vr) {
            *value = c->r[PAM_SIGNALS[k].r];
            return 1;
        }
    return 0;
}

double pam_next_breakpoint(const PamCore *c, double t_s) {
    double next = HUGE_VAL;
    int k, j;
    if (!scheduled(c)) return next;
    for (k = 0; k < PAM_NSIG; k++) {
        const PamSignal *s = &PAM_SIGNALS[k];
        if (s->n == 0 && s->time_s > t_s) next = fmin(next, s->time_s);
        for (j = 0; j < s->n; j++)
            if (s->t_s[j] > t_s) {
                next = fmin(next, s->t_s[j]);
                break;
            }
    }
    return next;
}

int pam_at_breakpoint(const PamCore *c, double t_s) {
    int k, j;
    if (!scheduled(c)) return 0;
    for (k = 0; k < PAM_NSIG; k++) {
        const PamSignal *s = &PAM_SIGNALS[k];
        if (s->n == 0 && s->time_s == t_s) return 1;
        for (j = 0; j < s->n; j++)
            if (s->t_s[j] == t_s) return 1;
    }
    return 0;
}

/* 1 if no input changes from t_s to the next breakpoint: a held load whose chamber does not change then
 * stays as it is until there. */
int pam_inputs_constant(const PamCore *c, double t_s) {
    int k;
    if (!scheduled(c)) return 1;
    for (k = 0; k < PAM_NSIG; k++) {
        const PamSignal *s = &PAM_SIGNALS[k];
        if (s->n == 0) {
            if (t_s >= s->time_s && s->initial != s->final) return 0;
        } else {
            int j = 0;
            while (j < s->n && s->t_s[j] <= t_s) j++;
            if (j > 0 && j < s->n && s->value[j - 1] != s->value[j]) return 0;
        }
    }
    return 1;
}

/* input_source = scenario: the FMU has signals, and each stays in its input's range at every knot
 * (the rating and the other parameters may have been changed since the build). */
int pam_check_signals(PamCore *c) {
    int k, j, bad = 0;
    if (PAM_NSIG == 0) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: input_source = 1 (scenario): this FMU was built without a "
                 "scenario (build it with pamsim fmu build --scenario)");
        return -1;
    }
    for (k = 0; k < PAM_NSIG; k++) {
        const PamSignal *s = &PAM_SIGNALS[k];
        double now = signal_value(s, c->time_s, 0);
        if ((c->inputs_set >> k & 1u) && c->r[s->r] != now) {
            pam_logf(c, PAM_LOG_ERROR, "invalid parameters: %s = %g, set by the importer: this FMU's inputs follow "
                     "the signals of the scenario it was built from (input_source = scenario; %g at t = %g s); set "
                     "input_source = importer (0) to drive them", PAM_VARS[s->vr - 1].name, c->r[s->r], now,
                     c->time_s);
            bad = -1;
        }
    }
    for (k = 0; k < PAM_NSIG; k++) {
        const PamSignal *s = &PAM_SIGNALS[k];
        int n = s->n ? s->n : 2;
        for (j = 0; j < n; j++) {
            double value = s->n ? s->value[j] : j ? s->final : s->initial;
            if (pam_check_value(c, s->vr, value)) {
                pam_logf(c, PAM_LOG_ERROR, "invalid parameters: input_source = 1 (scenario): the scenario's signal "
                         "of %s leaves the input's range", PAM_VARS[s->vr - 1].name);
                bad = -1;
                break;
            }
        }
    }
    return bad;
}
