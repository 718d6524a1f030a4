/* pamsim native backend: the C core as a shared library for pamsim.simulate(..., backend="native").
 *
 * Not part of the FMU.  Two entry points, both called once per batch through ctypes
 * (pamsim/native/library.py mirrors these layouts):
 *   pam_native_run_batch  integrates many cases, each from rest, with inputs that are constant over
 *                         given segments, and samples them on a uniform grid;
 *   pam_native_evaluate   evaluates the core's element functions at many states and parameter sets
 *                         (the conformance suite compares them with the Python elements).
 */
#ifndef PAM_NATIVE_H
#define PAM_NATIVE_H

#include <stdint.h>

#if defined(__GNUC__)
#define PAM_EXPORT __attribute__((visibility("default")))
#else
#define PAM_EXPORT
#endif

/* Inputs per segment, in this order: valve_command, supply_pressure_gauge_Pa,
 * prescribed_pressure_gauge_Pa, load_mass_kg, external_force_N. */
#define PAM_NATIVE_NU 5
/* Columns per sample: x, v, p_abs, air mass, W_muscle, E_friction, E_damping, W_external, E_impacts. */
#define PAM_NATIVE_NOUT 9
/* Columns per event: t, kind (PamEventKind), from mode, to mode, x, kinetic energy lost [J]. */
#define PAM_NATIVE_NEV 6
/* Quantities per point of pam_native_evaluate (see PamQuantity). */
#define PAM_NATIVE_NQ 17
#define PAM_NATIVE_MSG 256

/* pamsim.simulator event names. */
typedef enum { PAM_EV_VELOCITY_ZERO, PAM_EV_STOP_LOW, PAM_EV_STOP_HIGH, PAM_EV_RELEASE_UP, PAM_EV_RELEASE_DOWN } PamEventKind;
/* status of a case */
typedef enum { PAM_OK = 0, PAM_BAD_INPUT = 1, PAM_SOLVER_FAILED = 2, PAM_EVENTS_FULL = 3 } PamStatus;
typedef enum {
    Q_STATIC_FORCE, Q_COULOMB_LEVEL, Q_DAMPING_FORCE, Q_VALVE_FLOW, Q_PRESSURE_RATE,
    Q_RHS_X, Q_RHS_V, Q_RHS_P, Q_RHS_M, Q_INDICATOR_1, Q_INDICATOR_2, Q_NET_FORCE, Q_LEVEL_AT_REST,
    Q_REST_MODE, Q_VOLUME, Q_UPPER_STOP, Q_PRESSURE_GAUGE
} PamQuantity;

/* One call's cases.  Arrays are row-major; the offsets index the flattened per-case blocks. */
typedef struct {
    int64_t n_cases;
    const double *reals;          /* n_cases x PAM_NR: every real variable's value (parameters, input starts) */
    const int32_t *ints;          /* n_cases x PAM_NI */
    const double *duration_s;     /* n_cases */
    const int64_t *n_samples;     /* n_cases: samples at linspace(0, duration_s, n_samples) */
    const int64_t *sample_offset; /* n_cases: first row of the case in samples/modes */
    const int64_t *n_segments;    /* n_cases: input segments; the first starts at 0 */
    const int64_t *segment_offset;
    const double *segment_t_s;    /* start of each segment */
    const double *segment_u;      /* PAM_NATIVE_NU values at the start of each segment */
    const double *segment_du;     /* PAM_NATIVE_NU x 3 per segment, or NULL (held): input k follows
                                   * u_k + b (t - t0) + c (exp(-(t - t0) / tau) - 1) from the segment's start t0 */
    const int64_t *event_capacity; /* n_cases: rows available in events */
    const int64_t *event_offset;
    const int64_t *table_index;   /* n_cases: the case's static force table, or -1 (the core's built-in, none) */
    const double *table_grid;     /* per table: nx, np, x0 [m], dx [m], p0 [Pa], dp [Pa] */
    const int64_t *table_offset;  /* per table: its first node in table_nodes */
    const double *table_nodes;    /* every table's nodes x 4: F [N], F_x [N/m], F_p [N/Pa], F_xp [N/(m Pa)] */
    double *samples;              /* out: per case a PAM_NATIVE_NOUT x n_samples block (column-major) */
    int32_t *modes;               /* out: rows */
    double *events;               /* out: event rows x PAM_NATIVE_NEV */
    int64_t *n_events;            /* out: n_cases */
    int64_t *stats;               /* out: n_cases x 3: RHS evaluations, accepted steps, integration segments */
    int32_t *status;              /* out: n_cases, PamStatus */
    double *peaks;                /* out: n_cases x 3: largest x, smallest x, largest gauge pressure of the
                                     solution at every step end and event (samples may miss a peak) */
    char *messages;               /* out: n_cases x PAM_NATIVE_MSG, the first error */
} PamBatch;

/* Runs every case; returns the number of cases whose status is not PAM_OK. */
PAM_EXPORT int64_t pam_native_run_batch(const PamBatch *batch);
/* Evaluates PAM_NATIVE_NQ quantities at each of n points (parameters, states x, v, p_abs, m, mode). */
PAM_EXPORT void pam_native_evaluate(int64_t n, const double *reals, const int32_t *ints, const double *states,
                                    const int32_t *modes, double *out);
/* Sizes the Python side checks against its own layout before the first call. */
PAM_EXPORT int64_t pam_native_layout(int64_t which);

#endif
