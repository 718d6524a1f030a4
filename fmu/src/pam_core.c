/* pamsim muscle model core; see pam_core.h.  Every equation mirrors a
 * pamsim element (names given at each function) so the two can be compared. */
#include "pam_core.h"
#include "pam_force_table.h"
#include "pam_dopri.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define PA_PER_BAR PAM_PA_PER_BAR
#define PI 3.14159265358979323846
/* Event indicators are shifted by PAM_V_TOL_M_S and PAM_X_TOL_M (pam_shared.h) so that a new mode
 * starts strictly inside its region (v = 0 after a release is not an event) and the event test after
 * root location has the same margin on either side of the root. */
#define V_TOL_M_S PAM_V_TOL_M_S
#define X_TOL_M PAM_X_TOL_M
#define MIN_REBOUND_M_S PAM_MIN_REBOUND_M_S
#define MAX_ZERO_LENGTH_EVENTS PAM_MAX_ZERO_LENGTH_EVENTS

enum { X = 0, V = 1, P = 2, M = 3 };

static const PamTable BUILT_IN_TABLE = {PAM_FT_NX, PAM_FT_NP, PAM_FT_X0, PAM_FT_DX, PAM_FT_P0, PAM_FT_DP, PAM_FT};

void pam_reset(PamCore *c) {
    int k;
    c->table = &BUILT_IN_TABLE;
    for (k = 0; k < PAM_NVARS; k++) {
        if (PAM_VARS[k].kind == 'r') c->r[PAM_VARS[k].index] = PAM_VARS[k].start;
        else if (PAM_VARS[k].kind) c->i[PAM_VARS[k].index] = (int32_t)PAM_VARS[k].start;
    }
    c->time_s = 0.0;
    c->mode = PAM_STICK;
    c->inputs_changed = 0;
    c->h_s = 1e-4;
    c->n_steps = c->n_rhs = c->n_events = 0;
    c->table_edge_logged = 0;
    c->event_time_s = 0.0;
    c->inputs_set = 0;
}

/* ------------------------------------------------------------ inputs */

/* The inputs at t_s: a driver's closed form (inputs_fn), or the scenario's signals the FMU carries. */
static void core_inputs_at(PamCore *c, double t_s, int left) {
    if (c->inputs_fn) c->inputs_fn(c->inputs_env, c, t_s);
    else pam_inputs_at(c, t_s, left);
}

static int core_inputs_constant(const PamCore *c, double t_s) {
    return c->inputs_fn ? c->inputs_constant_fn(c->inputs_env) : pam_inputs_constant(c, t_s);
}

/* ------------------------------------------------------------ elements */

/* pamsim.static_models.geometry.Braid (b, N) */
static void braid_geometry(const double *r, double *b, double *n) {
    double theta = r[R_theta0_deg] * PI / 180.0;
    *b = r[R_L0_m] / cos(theta);
    *n = *b * sin(theta) / (2.0 * PI * r[R_r0_m]);
}

/* elements.stops: the upper stop the parameter x_high_m gives (the muscle's own, pamsim.muscle_setup), or
 * with x_high_m = 0 the braid lock at 54.7 deg from the geometry. */
static double upper_stop_m(const double *r) {
    double b, n;
    if (r[R_x_high_m] > 0.0) return r[R_x_high_m];
    braid_geometry(r, &b, &n);
    return r[R_L0_m] - b / sqrt(PAM_BRAID_LOCK_SEC2);
}

/* elements.chamber.MuscleChamber.volume_m3 / dvolume_dx_m2 */
static double volume_m3(const PamCore *c, double x) {
    double L = c->r[R_L0_m] - x, b = c->braid_b_m, n = c->braid_turns;
    return L * (b * b - L * L) / (4.0 * PI * n * n) + c->r[R_dead_volume_m3];
}

static double dvolume_dx_m2(const PamCore *c, double x) {
    double L = c->r[R_L0_m] - x, b = c->braid_b_m, n = c->braid_turns;
    return -(b * b - 3.0 * L * L) / (4.0 * PI * n * n);
}

static double pressure_gauge_Pa(const PamCore *c, const double *y) {
    if (c->i[I_pressure_source] == PAM_SOURCE_PRESCRIBED) return c->r[R_prescribed_pressure_gauge_Pa];
    return y[P] - c->r[R_p_atm_Pa];
}

static int has_table(const PamCore *c) {
    return c->table != NULL && c->table->nx >= 2 && c->table->np >= 2;
}

/* The table built into the FMU never extrapolates: its contraction range bounds the travel (the end
 * stops, pam_initialize; a travel beyond it is refused by pam_check_parameters) and a pressure beyond
 * its range takes the force at its edge (logged once).  A table given at run time (the native library,
 * tabulated over the scenario's stops and rating) extrapolates its edge cells, as the Python model it
 * stands for is evaluated there. */
static int table_guarded(const PamCore *c) {
    return c->i[I_static_force_model] == PAM_STATIC_FORCE_MODEL_TABLE && has_table(c) && c->table == &BUILT_IN_TABLE;
}

static double table_x_end_m(const PamTable *T) { return T->x0 + (T->nx - 1) * T->dx; }
static double table_p_end_Pa(const PamTable *T) { return T->p0 + (T->np - 1) * T->dp; }

/* The force table (pamsim.fmu.force_table; the FMU's baked in at build time, the native library's
 * given per case): bicubic Hermite interpolation of the value and the derivatives F_x, F_p, F_xp at
 * the four corners of the cell holding (x, p).  Outside the grid the edge cell's cubic extrapolates. */
static double table_force_N(const PamCore *c, double x, double p) {
    const PamTable *T = c->table;
    double u, w, s, t, f = 0.0;
    int i, j, a, b;
    /* No table (the parameter check refuses the choice; an initialisation-mode read may still get here). */
    if (!has_table(c)) return NAN;
    u = (x - T->x0) / T->dx;
    w = (p - T->p0) / T->dp;
    /* Clamped as doubles, so that a non-finite argument cannot make an out-of-range index. */
    i = (int)fmin(fmax(floor(u), 0.0), T->nx - 2.0);
    j = (int)fmin(fmax(floor(w), 0.0), T->np - 2.0);
    s = u - i;
    t = w - j;
    {
        /* Hermite basis: value and slope weights of the cell's low (0) and high (1) corner. */
        double vs[2] = {(2 * s - 3) * s * s + 1, (3 - 2 * s) * s * s}, ds[2] = {((s - 2) * s + 1) * s, (s - 1) * s * s};
        double vt[2] = {(2 * t - 3) * t * t + 1, (3 - 2 * t) * t * t}, dt[2] = {((t - 2) * t + 1) * t, (t - 1) * t * t};
        for (a = 0; a < 2; a++)
            for (b = 0; b < 2; b++) {
                const double *n = T->nodes[(i + a) * T->np + (j + b)];
                f += vs[a] * vt[b] * n[0] + ds[a] * T->dx * vt[b] * n[1] + vs[a] * dt[b] * T->dp * n[2]
                     + ds[a] * T->dx * dt[b] * T->dp * n[3];
            }
    }
    return f;
}

/* elements.static_force: the ACRA 2012 polynomial, exact (static_force_model 0), or the force table
 * of any other static model (1); clipped at zero as elements.force_clip does (a muscle cannot push) */
static double static_force_N(const PamCore *c, double x, double p_gauge) {
    const double *r = c->r;
    double p_bar = p_gauge / PA_PER_BAR, f;
    if (c->i[I_static_force_model] == PAM_STATIC_FORCE_MODEL_TABLE) {
        if (table_guarded(c)) {
            x = fmin(fmax(x, c->table->x0), table_x_end_m(c->table));
            p_gauge = fmin(fmax(p_gauge, c->table->p0), table_p_end_Pa(c->table));
        }
        f = table_force_N(c, x, p_gauge);
    } else f = ((r[R_K1_N_per_bar_m2] * x + r[R_K2_N_per_bar_m]) * x + r[R_C1_N_per_bar]) * p_bar
             + (r[R_S1_N_per_m2] * x + r[R_S2_N_per_m]) * x + r[R_S3_N];
    return f < 0.0 ? 0.0 : f;  /* NaN (a table choice without a table) stays NaN */
}

/* elements.friction: load-dependent (a negative level clamped at zero, or its magnitude:
 * friction_negative_level), constant, none */
static double coulomb_level_N(const PamCore *c, double x, double p_gauge) {
    const double *r = c->r;
    double level;
    switch (c->i[I_friction_model]) {
    case PAM_FRICTION_LOAD_DEPENDENT:
        level = (p_gauge / PA_PER_BAR - r[R_phi_bar_per_kg] * r[R_load_mass_kg])
                * ((r[R_N2_N_per_bar_m2] * x + r[R_N1_N_per_bar_m]) * x + r[R_N0_N_per_bar]);
        if (c->i[I_friction_negative_level] == PAM_FRICTION_NEGATIVE_LEVEL_ABS) return fabs(level);
        return level > 0.0 ? level : 0.0;
    case PAM_FRICTION_CONSTANT: return r[R_coulomb_constant_N];
    default: return 0.0;
    }
}

/* elements.damping: paper D1 v + D2 v|v|, linear |D1| v, none */
static double damping_force_N(const PamCore *c, double v) {
    switch (c->i[I_damping_model]) {
    case PAM_DAMPING_PAPER: return (c->r[R_D1_N_s_per_m] + c->r[R_D2_N_s2_per_m2] * fabs(v)) * v;
    case PAM_DAMPING_LINEAR: return fabs(c->r[R_D1_N_s_per_m]) * v;
    default: return 0.0;
    }
}

/* elements.valve.Iso6358Orifice.mass_flow_kg_s: signed flow from side a to side b */
static double orifice_flow_kg_s(const double *r, double pa, double pb, double Ta, double Tb) {
    int forward = pa >= pb;
    double p_up = forward ? pa : pb, p_down = forward ? pb : pa, T_up = forward ? Ta : Tb;
    double ratio = p_down / p_up, lam = r[R_valve_laminar_ratio], b = r[R_valve_b];
    double s = fmax(fmin(ratio, lam) - b, 0.0) / (1.0 - b);
    double laminar_scale = fmin(1.0, (1.0 - ratio) / (1.0 - lam));
    double flow = r[R_valve_C_m3_per_s_Pa] * r[R_rho0_kg_m3] * p_up * sqrt(r[R_T0_K] / T_up)
                  * sqrt(1.0 - s * s) * laminar_scale;
    return forward ? flow : -flow;
}

/* elements.pressure_source.ValveChamberSource.derivatives */
static void chamber_derivatives(const PamCore *c, const double *y, double v, double *dp, double *dm) {
    const double *r = c->r;
    double p = y[P], m = y[M], u = r[R_valve_command];
    double Vol = volume_m3(c, y[X]);
    double T_gas = p * Vol / (m * r[R_R_J_per_kg_K]);
    double T_sup = r[R_T_supply_K];
    double u_s = fmin(fmax(u, 0.0), 1.0), u_e = fmin(fmax(-u, 0.0), 1.0);
    double mdot = 0.0, T_in, dV;
    if (u_s > 0.0)
        mdot += u_s * orifice_flow_kg_s(r, r[R_supply_pressure_gauge_Pa] + r[R_p_atm_Pa], p, T_sup, T_gas);
    if (u_e > 0.0) mdot += u_e * orifice_flow_kg_s(r, r[R_p_atm_Pa], p, T_sup, T_gas);
    T_in = mdot >= 0.0 ? T_sup : T_gas;
    dV = dvolume_dx_m2(c, y[X]) * v;
    *dp = r[R_polytropic_index] * (r[R_R_J_per_kg_K] * T_in * mdot - p * dV) / Vol;
    *dm = mdot;
}

/* MuscleModel.rest_forces: net force at zero velocity and the Coulomb level [N] */
static void rest_forces(const PamCore *c, const double *y, double *net, double *level) {
    double p = pressure_gauge_Pa(c, y);
    *net = static_force_N(c, y[X], p) - c->r[R_load_mass_kg] * c->r[R_g_m_s2] + c->r[R_external_force_N];
    *level = coulomb_level_N(c, y[X], p);
}

/* MuscleModel.slip_rhs / held_rhs */
static void rhs(PamCore *c, int mode, const double *y, double *dy) {
    const double *r = c->r;
    int slip = mode == PAM_SLIP_UP || mode == PAM_SLIP_DOWN;
    double v = slip ? y[V] : 0.0;
    c->n_rhs++;
    if (slip) {
        double p = pressure_gauge_Pa(c, y), m = r[R_load_mass_kg];
        double F = static_force_N(c, y[X], p) - damping_force_N(c, v) - (double)mode * coulomb_level_N(c, y[X], p)
                   - m * r[R_g_m_s2] + r[R_external_force_N];
        dy[X] = v;
        dy[V] = F / m;
    } else {
        dy[X] = 0.0;
        dy[V] = 0.0;
    }
    if (c->i[I_pressure_source] == PAM_SOURCE_VALVE) chamber_derivatives(c, y, v, &dy[P], &dy[M]);
    else dy[P] = dy[M] = 0.0;
}

/* Positive inside the current mode; a sign change is an event (simulator._Events). */
static void indicators(const PamCore *c, int mode, const double *y, double *z) {
    double net, level, eps = c->r[R_release_margin_N];
    switch (mode) {
    case PAM_SLIP_UP: z[0] = y[V] + V_TOL_M_S; z[1] = c->x_high_m + X_TOL_M - y[X]; return;
    case PAM_SLIP_DOWN: z[0] = V_TOL_M_S - y[V]; z[1] = y[X] - c->x_low_m + X_TOL_M; return;
    default: break;
    }
    rest_forces(c, y, &net, &level);
    z[0] = mode == PAM_STOP_HIGH ? 1.0 : level + eps - net;
    z[1] = mode == PAM_STOP_LOW ? 1.0 : level + eps + net;
}

/* simulator._rest_mode: slip if the net force beats friction by stick_margin_N, else held */
static int rest_mode(const PamCore *c, const double *y, int where) {
    double net, level, margin = c->r[R_stick_margin_N];
    rest_forces(c, y, &net, &level);
    if (where != PAM_STOP_HIGH && net - level > margin) return PAM_SLIP_UP;
    if (where != PAM_STOP_LOW && -net - level > margin) return PAM_SLIP_DOWN;
    return where;
}

static void get_states(const PamCore *c, double *y) {
    int k;
    for (k = 0; k < PAM_NX; k++) y[k] = c->r[PAM_STATE_R[k]];
}

static void put_states(PamCore *c, const double *y) {
    int k;
    for (k = 0; k < PAM_NX; k++) c->r[PAM_STATE_R[k]] = y[k];
}

/* ------------------------------------------------------------ checks */

int pam_check_value(PamCore *c, unsigned vr, double value) {
    const PamVarInfo *info;
    /* An input's own range, generated from pamsim/fmu/variables.py (load_mass_kg: pamsim.parameters.LOAD_MASS). */
    if (pam_check_own_range(c, vr, value)) return -1;
    if (vr < 1 || vr > PAM_NVARS) return 0;
    info = &PAM_VARS[vr - 1];
    if ((vr == VR_supply_pressure_gauge_Pa || vr == VR_prescribed_pressure_gauge_Pa)
        && value > c->r[R_rated_pressure_gauge_Pa]) {
        pam_logf(c, PAM_LOG_ERROR, "%s = %g Pa: exceeds the muscle's rating rated_pressure_gauge_Pa = %g Pa",
                 info->name, value, c->r[R_rated_pressure_gauge_Pa]);
        return -1;
    }
    if (vr == VR_prescribed_pressure_gauge_Pa && value < -c->r[R_p_atm_Pa]) {
        pam_logf(c, PAM_LOG_ERROR, "prescribed_pressure_gauge_Pa = %g Pa: below vacuum", value);
        return -1;
    }
    return 0;
}

/* The value of the real variable called `name` (the order checks name parameters; NaN if none is). */
static double named_real(const PamCore *c, const char *name) {
    int k;
    for (k = 0; k < PAM_NVARS; k++)
        if (PAM_VARS[k].kind == 'r' && strcmp(PAM_VARS[k].name, name) == 0) return c->r[PAM_VARS[k].index];
    return NAN;
}

/* The part of the table's range by which the same bound may differ when computed in Python (the
 * tabulated domain) and here: a few roundings. */
#define TABLE_COVER_TOL 1e-12

/* The built-in table covers the load's travel (0 to the braid lock) and the gauge pressures the chamber
 * starts and is driven at (0 to the rating, the bound of the supply, prescribed and initial pressures):
 * the table was built for one muscle, and the geometry or rating of another would leave it. */
static int check_table_covers(PamCore *c) {
    const double *r = c->r;
    const PamTable *T = c->table;
    double x_high = upper_stop_m(r), x_end = table_x_end_m(T), p_end = table_p_end_Pa(T);
    double x_tol = TABLE_COVER_TOL * (x_end - T->x0), p_tol = TABLE_COVER_TOL * (p_end - T->p0);
    int bad = 0;
    if (x_high > x_end + x_tol || T->x0 > x_tol) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: L0_m = %g, theta0_deg = %g, x_high_m = %g: the load's travel, "
                 "0 to %.6g m (the upper stop), leaves the force table of %s, which covers contraction %.6g to %.6g m "
                 "(a table is built for one muscle: build the FMU for this geometry)", r[R_L0_m], r[R_theta0_deg],
                 r[R_x_high_m], x_high, PAM_FT_MODEL, T->x0, x_end);
        bad = -1;
    }
    if (r[R_rated_pressure_gauge_Pa] > p_end + p_tol) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: rated_pressure_gauge_Pa = %g: above the force table of %s, "
                 "which covers gauge pressure %g to %g Pa (the supply, prescribed and initial pressures may reach "
                 "the rating)", r[R_rated_pressure_gauge_Pa], PAM_FT_MODEL, T->p0, p_end);
        bad = -1;
    }
    if (T->p0 > p_tol) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: static_force_model = 1 (table): the force table of %s starts "
                 "at gauge pressure %g Pa, above the ambient pressure an exhausted chamber reaches", PAM_FT_MODEL,
                 T->p0);
        bad = -1;
    }
    return bad;
}

int pam_check_parameters(PamCore *c) {
    const double *r = c->r;
    int bad = 0, k;
    double x_high;
    /* Each parameter's own range, generated from pamsim/fmu/variables.py (the Python Parameter bounds). */
    if (pam_check_parameter_ranges(c)) return -1;
    /* Checks between parameters (ParameterSet.violations) and of the FMU's own parameters. */
    for (k = 0; k < PAM_N_ORDER_CHECKS; k++) {
        double a = named_real(c, PAM_ORDER_CHECKS[k][0]), below = named_real(c, PAM_ORDER_CHECKS[k][1]);
        if (!(a < below)) {
            pam_logf(c, PAM_LOG_ERROR, "invalid parameters: %s = %g: must be below %s = %g", PAM_ORDER_CHECKS[k][0], a,
                     PAM_ORDER_CHECKS[k][1], below);
            bad = -1;
        }
    }
    if (!(r[R_release_margin_N] > r[R_stick_margin_N])) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: release_margin_N = %g: must be above stick_margin_N = %g",
                 r[R_release_margin_N], r[R_stick_margin_N]);
        bad = -1;
    }
    if (c->i[I_static_force_model] == PAM_STATIC_FORCE_MODEL_TABLE && !has_table(c)) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: static_force_model = 1 (table): this FMU was built without "
                 "a force table (build it with pamsim fmu build --scenario)");
        bad = -1;
    }
    if (table_guarded(c) && check_table_covers(c)) bad = -1;
    if (c->i[I_input_source] == PAM_INPUT_SOURCE_SCENARIO && pam_check_signals(c)) bad = -1;
    if (!(r[R_initial_pressure_gauge_Pa] <= r[R_rated_pressure_gauge_Pa])) {
        pam_logf(c, PAM_LOG_ERROR,
                 "invalid parameters: initial_pressure_gauge_Pa = %g: must be at most rated_pressure_gauge_Pa = %g",
                 r[R_initial_pressure_gauge_Pa], r[R_rated_pressure_gauge_Pa]);
        bad = -1;
    }
    for (k = 0; k < PAM_NVARS; k++)
        if (PAM_VARS[k].causality == PAM_INPUT && pam_check_value(c, (unsigned)k + 1, r[PAM_VARS[k].index])) bad = -1;
    if (bad) return -1;
    if (r[R_x_high_m] > 0.0 && !(r[R_x_high_m] < r[R_L0_m])) {
        pam_logf(c, PAM_LOG_ERROR, "invalid parameters: x_high_m = %g: the upper stop must be below the rest length "
                 "L0_m = %g (x_high_m = 0: the braid lock from the geometry)", r[R_x_high_m], r[R_L0_m]);
        return -1;
    }
    x_high = upper_stop_m(r);
    if (!(r[R_initial_contraction_m] >= 0.0 && r[R_initial_contraction_m] <= x_high)) {
        pam_logf(c, PAM_LOG_ERROR,
                 "invalid parameters: initial_contraction_m = %g: must lie between the stops, 0 and %.4f m "
                 "(the upper stop)", r[R_initial_contraction_m], x_high);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ state and outputs */

/* A pressure (or a contraction) further outside the built-in table than this part of its range is
 * reported: the force there is the table's edge value, not the model's.  Closer, it is the chamber's
 * ordinary overshoot of a supply at the rating (the table's top) as the load swings back, or its dip
 * below ambient as the muscle swells, where the edge value is as good as the model's. */
#define TABLE_EDGE_REPORT 1e-2

static void note_table_edge(PamCore *c, double t, const double *y) {
    const PamTable *T = c->table;
    double p, x_end, p_end, x_tol, p_tol;
    if (c->table_edge_logged || !table_guarded(c)) return;
    p = pressure_gauge_Pa(c, y);
    x_end = table_x_end_m(T);
    p_end = table_p_end_Pa(T);
    x_tol = TABLE_EDGE_REPORT * (x_end - T->x0);
    p_tol = TABLE_EDGE_REPORT * (p_end - T->p0);
    if (p < T->p0 - p_tol || p > p_end + p_tol) {
        pam_logf(c, PAM_LOG_WARNING, "at t = %.9g s the chamber's gauge pressure, %g Pa, left the force table of %s "
                 "(%g to %g Pa): the static force is held at the table's edge, never extrapolated (reported once)",
                 t, p, PAM_FT_MODEL, T->p0, p_end);
        c->table_edge_logged = 1;
    } else if (y[X] < T->x0 - x_tol || y[X] > x_end + x_tol) {
        pam_logf(c, PAM_LOG_WARNING, "at t = %.9g s the contraction, %g m, left the force table of %s (%g to %g m): "
                 "the static force is held at the table's edge, never extrapolated (reported once)", t, y[X],
                 PAM_FT_MODEL, T->x0, x_end);
        c->table_edge_logged = 1;
    }
}

/* Geometry, stops, the state at rest and its mode, from the parameters and the inputs as they are. */
static void derive_start(PamCore *c) {
    double y[PAM_NX], b, n;
    braid_geometry(c->r, &b, &n);
    c->braid_b_m = b;
    c->braid_turns = n;
    c->x_low_m = 0.0;
    c->x_high_m = upper_stop_m(c->r);
    if (table_guarded(c)) { /* the table's edge is a stop: the travel within it up to rounding (checked) */
        c->x_low_m = fmax(c->x_low_m, c->table->x0);
        c->x_high_m = fmin(c->x_high_m, table_x_end_m(c->table));
    }
    y[X] = c->r[R_initial_contraction_m];
    y[V] = 0.0;
    y[P] = c->r[R_p_atm_Pa] + c->r[R_initial_pressure_gauge_Pa]; /* ValveChamberSource.initial_state */
    y[M] = y[P] * volume_m3(c, y[X]) / (c->r[R_R_J_per_kg_K] * c->r[R_T_supply_K]);
    put_states(c, y);
    /* simulator.initial_mode */
    c->mode = rest_mode(c, y, y[X] <= c->x_low_m ? PAM_STOP_LOW : y[X] >= c->x_high_m ? PAM_STOP_HIGH : PAM_STICK);
    c->inputs_changed = 0;
    pam_evaluate(c);
}

void pam_initialize(PamCore *c) {
    double y[PAM_NX];
    pam_apply_signals(c, c->time_s, 0, c->inputs_set); /* the ones the importer set are checked equal */
    derive_start(c);
    get_states(c, y);
    c->table_edge_logged = 0; /* a run starts */
    note_table_edge(c, c->time_s, y);
}

void pam_evaluate(PamCore *c) {
    double y[PAM_NX], dy[PAM_NX], z[PAM_NZ], net, level, friction;
    int k, mode = c->mode;
    get_states(c, y);
    rhs(c, mode, y, dy);
    for (k = 0; k < PAM_NX; k++) c->r[PAM_DERIV_R[k]] = dy[k];
    indicators(c, mode, y, z);
    c->r[R_event_indicator_1] = z[0];
    c->r[R_event_indicator_2] = z[1];
    rest_forces(c, y, &net, &level);
    /* MuscleModel.breakdown: sliding -> -mode F_c; held -> friction takes what it can, the stop the rest */
    if (mode == PAM_SLIP_UP || mode == PAM_SLIP_DOWN) friction = -(double)mode * level;
    else if (mode == PAM_STICK || (mode == PAM_STOP_LOW && net > 0.0) || (mode == PAM_STOP_HIGH && net < 0.0))
        friction = -net;
    else friction = 0.0;
    c->r[R_p_gauge_Pa] = pressure_gauge_Pa(c, y);
    c->r[R_F_static_N] = static_force_N(c, y[X], c->r[R_p_gauge_Pa]);
    c->r[R_F_friction_N] = friction;
    c->i[I_friction_mode] = mode;
}

void pam_note_table_edge(PamCore *c) {
    double y[PAM_NX];
    get_states(c, y);
    note_table_edge(c, c->time_s, y);
}

/* ------------------------------------------------------------ events */

/* simulator._transition, decided from the state instead of from the event's name */
static int transition(PamCore *c, double *y) {
    int mode = c->mode;
    if (mode == PAM_SLIP_UP || mode == PAM_SLIP_DOWN) {
        int up = mode == PAM_SLIP_UP;
        if (up ? y[X] >= c->x_high_m : y[X] <= c->x_low_m) {
            double rebound = c->r[R_stop_restitution] * fabs(y[V]);
            y[X] = up ? c->x_high_m : c->x_low_m;
            if (rebound > MIN_REBOUND_M_S) {
                y[V] = up ? -rebound : rebound;
                c->mode = up ? PAM_SLIP_DOWN : PAM_SLIP_UP;
            } else {
                y[V] = 0.0;
                c->mode = rest_mode(c, y, up ? PAM_STOP_HIGH : PAM_STOP_LOW);
            }
            return 1;
        }
        if (up ? y[V] <= 0.0 : y[V] >= 0.0) {
            y[V] = 0.0;
            c->mode = rest_mode(c, y, PAM_STICK);
            return 1;
        }
        return 0;
    }
    c->mode = rest_mode(c, y, mode);
    return 0;
}

int pam_event_update(PamCore *c) {
    double y[PAM_NX];
    int old = c->mode, jumped;
    get_states(c, y);
    note_table_edge(c, c->time_s, y);
    jumped = transition(c, y);
    if (jumped || c->mode != old) c->n_events++;
    put_states(c, y);
    c->inputs_changed = 0;
    pam_evaluate(c);
    return jumped;
}

/* ------------------------------------------------------------ Dormand-Prince 5(4) */

/* The nodes of the tableau of pam_dopri.h: the right-hand side depends on time through the inputs, held
 * over a communication step, or following the scenario's signals (input_source = scenario), which are
 * set at each stage's node. */
static const double DP_C[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};

typedef struct {
    double k[7][PAM_NX];
} DpStages;

/* One trial step from t0; returns the scaled RMS error norm. k[0] must hold f(t0, y0).  The inputs are
 * left at their values from the left of t0 + h. */
static double dp_step(PamCore *c, double t0, const double *y0, double h, DpStages *s, double *y1) {
    double yt[PAM_NX], err = 0.0, rtol = c->r[R_cs_relative_tolerance];
    int st, j, n;
    for (st = 1; st < 7; st++) {
        for (n = 0; n < PAM_NX; n++) {
            double acc = 0.0;
            for (j = 0; j < st; j++) acc += DP_A[st][j] * s->k[j][n];
            yt[n] = y0[n] + h * acc;
        }
        core_inputs_at(c, t0 + DP_C[st] * h, 1);
        rhs(c, c->mode, yt, s->k[st]);
    }
    for (n = 0; n < PAM_NX; n++) {
        double e = 0.0, sc;
        y1[n] = yt[n]; /* stage 7 is evaluated at the 5th-order solution (FSAL) */
        for (st = 0; st < 7; st++) e += DP_E[st] * s->k[st][n];
        sc = rtol * PAM_NOMINAL[n] + rtol * fmax(fabs(y0[n]), fabs(y1[n]));
        err += (h * e / sc) * (h * e / sc);
    }
    return sqrt(err / PAM_NX);
}

static void dp_dense(const DpStages *s, const double *y0, double h, double th, double *y) {
    double pw[4] = {th, th * th, th * th * th, th * th * th * th};
    int n, st, j;
    for (n = 0; n < PAM_NX; n++) {
        double acc = 0.0;
        for (st = 0; st < 7; st++) {
            double q = 0.0;
            for (j = 0; j < 4; j++) q += DP_P[st][j] * pw[j];
            acc += s->k[st][n] * q;
        }
        y[n] = y0[n] + h * acc;
    }
}

/* The smallest of the indicators in `which` (bit k: indicator k) at y. */
static double min_indicator_of(const PamCore *c, const double *y, unsigned which) {
    double z[PAM_NZ], m = INFINITY;
    int k;
    indicators(c, c->mode, y, z);
    for (k = 0; k < PAM_NZ; k++)
        if ((which >> k) & 1u) m = fmin(m, z[k]);
    return m;
}

static double min_indicator(const PamCore *c, const double *y) { return min_indicator_of(c, y, ~0u); }

/* The indicators at or below zero at y (bit k: indicator k). */
static unsigned crossed_indicators(const PamCore *c, const double *y) {
    double z[PAM_NZ];
    unsigned crossed = 0;
    int k;
    indicators(c, c->mode, y, z);
    for (k = 0; k < PAM_NZ; k++)
        if (z[k] <= 0.0) crossed |= 1u << k;
    return crossed;
}

static int sliding(int mode) { return mode == PAM_SLIP_UP || mode == PAM_SLIP_DOWN; }

/* Where an indicator first reaches zero over an accepted step, as a fraction of the step in
 * (lo, hi], and which indicators are at or below zero at hi (0 if none is).  A sliding step is
 * checked at its end (cs_max_step_s keeps it short against a sign change and back).  A held load's
 * step is not limited by cs_max_step_s (its chamber pressure moves monotonically toward its source,
 * so its force margins seldom turn back), so a long one is also checked at HELD_CHECKS points of its
 * dense output.  An indicator crosses where its sign changes between two checked points, as in the
 * generic engine (pam_engine.c, which says why). */
#define HELD_CHECKS 16
static unsigned first_crossing(PamCore *c, const DpStages *s, double t, const double *y, const double *y1,
                               double h, double *lo, double *hi) {
    int n = (!sliding(c->mode) && h > c->r[R_cs_max_step_s]) ? HELD_CHECKS : 1, k;
    double ye[PAM_NX];
    for (k = 1; k <= n; k++) {
        unsigned crossed;
        if (k < n) dp_dense(s, y, h, (double)k / n, ye);
        core_inputs_at(c, k < n ? t + (double)k / n * h : t + h, 1);
        crossed = crossed_indicators(c, k < n ? ye : y1);
        if (crossed) {
            *lo = (double)(k - 1) / n;
            *hi = (double)k / n;
            return crossed;
        }
    }
    return 0;
}

/* A held load's chamber within the integrator's error scale of its source's pressure is set to that
 * pressure (its air mass moved by the same amount of gas), so that its derivatives are exactly zero:
 * the rest of its exponential approach is below the tolerance, and an explicit integrator would
 * follow it in steps of the chamber's time constant (milliseconds) for ever.  Not where the change
 * would cross an event indicator.  Returns 1 if it changed y. */
static int settle_chamber(PamCore *c, double *y) {
    const double *r = c->r;
    double u = r[R_valve_command], p_src, dp, vol, T_in, settled[PAM_NX];
    if (sliding(c->mode) || c->i[I_pressure_source] != PAM_SOURCE_VALVE || u == 0.0) return 0;
    p_src = u > 0.0 ? r[R_supply_pressure_gauge_Pa] + r[R_p_atm_Pa] : r[R_p_atm_Pa];
    dp = p_src - y[P];
    if (dp == 0.0 || !(fabs(dp) <= r[R_cs_relative_tolerance] * (PAM_NOMINAL[P] + fabs(p_src)))) return 0;
    vol = volume_m3(c, y[X]);
    T_in = dp > 0.0 ? r[R_T_supply_K] : y[P] * vol / (y[M] * r[R_R_J_per_kg_K]);
    memcpy(settled, y, sizeof settled);
    settled[P] = p_src;
    settled[M] += dp * vol / (r[R_polytropic_index] * r[R_R_J_per_kg_K] * T_in);
    if (min_indicator(c, settled) <= 0.0) return 0;
    memcpy(y, settled, sizeof settled);
    return 1;
}

/* Leaves the instance at the last instant reached (time, states, mode and outputs agree) and fails. */
static int step_failed(PamCore *c, double t, const double *y) {
    c->time_s = t;
    core_inputs_at(c, t, 0);
    put_states(c, y);
    pam_evaluate(c);
    return -1;
}

/* simulator: a held load's mode is decided again where its inputs jump or reach a breakpoint. */
static void recheck_held(PamCore *c, const double *y) {
    int old = c->mode;
    if (sliding(c->mode)) return;
    c->mode = rest_mode(c, y, c->mode);
    if (c->mode != old) c->n_events++;
}

/* The end of the piece of [t, t_end] the integrator crosses next: t_end, or the first breakpoint of the
 * signals before it (they are smooth in between). */
static double piece_end(const PamCore *c, double t, double t_end) {
    return fmin(t_end, pam_next_breakpoint(c, t));
}

int pam_do_step(PamCore *c, double t_end) {
    double y[PAM_NX], y1[PAM_NX], t = c->time_s, h_max = c->r[R_cs_max_step_s], t_piece;
    DpStages s;
    long steps = 0, max_steps = c->i[I_cs_max_internal_steps];
    int zero_length = 0, n;
    get_states(c, y);
    core_inputs_at(c, t, 0);
    if (c->inputs_changed || pam_at_breakpoint(c, t)) recheck_held(c, y);
    c->inputs_changed = 0;
    rhs(c, c->mode, y, s.k[0]);
    t_piece = piece_end(c, t, t_end);
    /* A remainder below the time resolution (left by an event located just before t_end) is not a step. */
    while (t_end - t > 1e-13 * fmax(1.0, fabs(t_end))) {
        double h, err, factor, lo = 0.0, hi = 1.0;
        unsigned crossed;
        int last, at_rest = !sliding(c->mode);
        if (t_piece - t <= 1e-13 * fmax(1.0, fabs(t_piece))) {
            /* A breakpoint of the signals: they take their values from the right. */
            t = t_piece;
            core_inputs_at(c, t, 0);
            recheck_held(c, y);
            rhs(c, c->mode, y, s.k[0]);
            t_piece = piece_end(c, t, t_end);
            continue;
        }
        core_inputs_at(c, t, 0); /* a rejected trial step left them at its end */
        if (settle_chamber(c, y)) rhs(c, c->mode, y, s.k[0]);
        /* A held load whose chamber does not change stays as it is while the inputs are held:
         * the solution is constant, however long the step. */
        for (n = 0; n < PAM_NX && at_rest; n++) at_rest = s.k[0][n] == 0.0;
        if (at_rest && core_inputs_constant(c, t)) {
            if (c->on_step) c->on_step(c->step_env, t, t_piece, 0.0, y, NULL);
            t = t_piece;
            continue;
        }
        h = fmin(sliding(c->mode) ? fmin(c->h_s, h_max) : c->h_s, t_piece - t);
        last = h >= t_piece - t;
        if (++steps > max_steps) {
            pam_logf(c, PAM_LOG_ERROR, "more than %ld internal steps (cs_max_internal_steps) between t = %.9g s "
                     "and %.9g s", max_steps, c->time_s, t_end);
            return step_failed(c, t, y);
        }
        if (h < 1e-14 * fmax(1.0, fabs(t))) {
            pam_logf(c, PAM_LOG_ERROR, "step size underflow at t = %.9g s", t);
            return step_failed(c, t, y);
        }
        err = dp_step(c, t, y, h, &s, y1);
        if (!(err <= 1.0)) {
            c->h_s = h * (isfinite(err) ? fmax(0.2, 0.9 * pow(err, -0.2)) : 0.1);
            continue;
        }
        factor = err == 0.0 ? 10.0 : fmin(10.0, fmax(0.2, 0.9 * pow(err, -0.2)));
        c->n_steps++;
        if ((crossed = first_crossing(c, &s, t, y, y1, h, &lo, &hi)) != 0) {
            /* Locate the first crossing of the indicators that crossed on the dense output; keep the
             * far side so that the event test holds. */
            double ye[PAM_NX];
            int it;
            for (it = 0; it < 100 && (hi - lo) * h > 1e-15 * fmax(1.0, fabs(t)); it++) {
                double mid = 0.5 * (lo + hi);
                dp_dense(&s, y, h, mid, ye);
                core_inputs_at(c, t + mid * h, 1);
                if (min_indicator_of(c, ye, crossed) <= 0.0) hi = mid;
                else lo = mid;
            }
            if (hi < 1.0) dp_dense(&s, y, h, hi, ye);
            else memcpy(ye, y1, sizeof ye);
            if (c->on_step) c->on_step(c->step_env, t, hi < 1.0 ? t + hi * h : (last ? t_piece : t + h), h, y, &s);
            t = hi < 1.0 ? t + hi * h : (last ? t_piece : t + h);
            core_inputs_at(c, t, 1);
            memcpy(y, ye, sizeof y);
            put_states(c, y);
            note_table_edge(c, t, y);
            {
                double y_before[PAM_NX];
                int old = c->mode, jumped;
                memcpy(y_before, y, sizeof y_before);
                jumped = transition(c, y);
                if (!jumped && c->mode == old) {
                    if (++zero_length > MAX_ZERO_LENGTH_EVENTS) {
                        pam_logf(c, PAM_LOG_ERROR, "event switching made no progress at t = %.9g s", t);
                        return step_failed(c, t, y);
                    }
                } else {
                    zero_length = 0;
                    c->n_events++;
                    if (c->on_event) c->on_event(c->event_env, t, old, c->mode, y_before, y);
                }
            }
            c->h_s = fmax(fmin(h * hi, h_max), 1e-6);
            rhs(c, c->mode, y, s.k[0]);
            continue;
        }
        if (c->on_step) c->on_step(c->step_env, t, last ? t_piece : t + h, h, y, &s);
        t = last ? t_piece : t + h;
        memcpy(y, y1, sizeof y);
        memcpy(s.k[0], s.k[6], sizeof s.k[0]);
        note_table_edge(c, t, y);
        if (!last || factor < 1.0) c->h_s = h * factor;
    }
    c->time_s = t_end;
    core_inputs_at(c, t_end, 0);
    put_states(c, y);
    pam_evaluate(c);
    note_table_edge(c, t_end, y);
    return 0;
}

/* ------------------------------------------------------------ directional derivatives */

static double *value_ptr(PamCore *c, unsigned vr) {
    if (vr < 1 || vr > PAM_NVARS || PAM_VARS[vr - 1].kind != 'r') return 0;
    return &c->r[PAM_VARS[vr - 1].index];
}

/* The scale of a known's finite-difference step: its value, or where that is zero its nominal
 * (states), its start value, or 1. */
static double known_scale(unsigned vr, double value) {
    int k;
    if (value != 0.0) return fabs(value);
    for (k = 0; k < PAM_NX; k++)
        if (PAM_STATE_R[k] == PAM_VARS[vr - 1].index) return PAM_NOMINAL[k];
    return PAM_VARS[vr - 1].start != 0.0 ? fabs(PAM_VARS[vr - 1].start) : 1.0;
}

/* sum_k seed[k] d(unknowns)/d(knowns[k]): one central difference per known, each with a step
 * relative to that known's own scale, since the knowns may be of any scale (m and Pa) and a seed
 * may hold zeros. */
int pam_directional_derivative(PamCore *c, const unsigned *unknowns, int n_unknowns, const unsigned *knowns,
                               int n_knowns, const double *seed, double *sensitivity, int initializing) {
    /* In initialisation mode the states, the geometry and the stops follow the parameters: each side of
     * a difference derives them again, as the end of initialisation will. */
    void (*evaluate)(PamCore *) = initializing ? derive_start : pam_evaluate;
    PamCore saved_core = *c;
    double saved[PAM_NR], up[PAM_NR];
    int k, u;
    for (k = 0; k < n_knowns; k++)
        if (!value_ptr(c, knowns[k])) return -1;
    for (u = 0; u < n_unknowns; u++) {
        if (!value_ptr(c, unknowns[u])) return -1;
        sensitivity[u] = 0.0;
    }
    memcpy(saved, c->r, sizeof saved);
    for (k = 0; k < n_knowns; k++) {
        double *known = value_ptr(c, knowns[k]), h;
        if (seed[k] == 0.0) continue;
        h = 1e-6 * known_scale(knowns[k], *known);
        *known = saved[PAM_VARS[knowns[k] - 1].index] + h;
        evaluate(c);
        memcpy(up, c->r, sizeof up);
        *c = saved_core;
        *known = saved[PAM_VARS[knowns[k] - 1].index] - h;
        evaluate(c);
        for (u = 0; u < n_unknowns; u++) {
            int idx = PAM_VARS[unknowns[u] - 1].index;
            sensitivity[u] += seed[k] * (up[idx] - c->r[idx]) / (2.0 * h);
        }
        *c = saved_core;
    }
    return 0;
}

/* ------------------------------------------------------------ FMU state */

const char *pam_state_invalid(const PamCore *c) {
    if (c->mode < PAM_SLIP_DOWN || c->mode > PAM_STOP_HIGH) return "its load mode is not one of -1, 0, 1, 2, 3";
    if (!isfinite(c->time_s) || !(c->h_s > 0.0) || !isfinite(c->h_s)) return "its time or step is not finite";
    if (c->n_steps < 0 || c->n_rhs < 0 || c->n_events < 0) return "a count is negative";
    return NULL;
}

void pam_adopt_state(PamCore *c, const PamCore *from) {
    PamCore mine = *c;
    *c = *from;
    c->log = mine.log;
    c->log_env = mine.log_env;
    c->on_event = mine.on_event;
    c->event_env = mine.event_env;
    c->on_step = mine.on_step;
    c->step_env = mine.step_env;
    c->table = mine.table;
    c->inputs_fn = mine.inputs_fn;
    c->inputs_constant_fn = mine.inputs_constant_fn;
    c->inputs_env = mine.inputs_env;
}
