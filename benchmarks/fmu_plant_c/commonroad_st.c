/* CommonRoad's single-track car (vehiclemodels.vehicle_dynamics_st, with its steering and acceleration constraints
 * and its kinematic switch below 0.1 m/s) with the first-order steering actuator of examples/fmu_plant/
 * commonroad_st_plant.py, ported to C as an FMI 2.0 co-simulation FMU: the C FMU that benchmarks/fmu_plant.py times
 * beside the PythonFMU one. Same variables, value references and outputs as the example (rear-axle centre, SI).
 * The vehicle's parameters come from params.h, which the benchmark writes from CommonRoad's parameters_vehicle2. */

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "params.h"

#define N_OUT 8
#define VR_DELTA_CMD 0
#define VR_ACCEL_CMD 1
#define VR_V0 2
#define VR_FIRST_OUT 3
#define N_VR (VR_FIRST_OUT + N_OUT)
#define G_MPS2 9.81

typedef struct {
    double x[7];
    double delta_cmd, accel_cmd, v0;
    double out[N_OUT];
} Model;

static double steering_constraints(double angle, double rate) {
    if ((angle <= STEER_MIN && rate <= 0) || (angle >= STEER_MAX && rate >= 0)) return 0.0;
    if (rate <= STEER_V_MIN) return STEER_V_MIN;
    if (rate >= STEER_V_MAX) return STEER_V_MAX;
    return rate;
}

static double acceleration_constraints(double v, double a) {
    double pos_limit = v > V_SWITCH ? A_MAX * V_SWITCH / v : A_MAX;
    if ((v <= LONG_V_MIN && a <= 0) || (v >= LONG_V_MAX && a >= 0)) return 0.0;
    if (a <= -A_MAX) return -A_MAX;
    if (a >= pos_limit) return pos_limit;
    return a;
}

static void rhs(const Model *m, const double *x, double *f) {
    double u0 = (m->delta_cmd - x[2]) / STEERING_TIME_CONSTANT_S;
    double u1 = (x[3] <= 0.0 && m->accel_cmd < 0.0) ? 0.0 : m->accel_cmd;
    u0 = steering_constraints(x[2], u0);
    u1 = acceleration_constraints(x[3], u1);
    if (fabs(x[3]) < 0.1) {
        double lwb = P_A + P_B;
        double beta = atan(tan(x[2]) * P_B / lwb);
        f[0] = x[3] * cos(beta + x[4]);
        f[1] = x[3] * sin(beta + x[4]);
        f[2] = steering_constraints(x[2], u0);
        f[3] = acceleration_constraints(x[3], u1);
        f[4] = x[3] * cos(beta) * tan(x[2]) / lwb;
        double d_beta = (P_B * u0) / (lwb * pow(cos(x[2]), 2) * (1 + pow(pow(tan(x[2]), 2) * P_B / lwb, 2)));
        double dd_psi = 1 / lwb * (u1 * cos(x[6]) * tan(x[2]) - x[3] * sin(x[6]) * d_beta * tan(x[2]) +
                                   x[3] * cos(x[6]) * u0 / pow(cos(x[2]), 2));
        f[5] = dd_psi;
        f[6] = d_beta;
        return;
    }
    double lf = P_A, lr = P_B, h = P_H_S, mass = P_M, inertia = P_I_Z, mu = P_MU, csf = P_C_S, csr = P_C_S;
    double g = G_MPS2;
    f[0] = x[3] * cos(x[6] + x[4]);
    f[1] = x[3] * sin(x[6] + x[4]);
    f[2] = u0;
    f[3] = u1;
    f[4] = x[5];
    f[5] = -mu * mass / (x[3] * inertia * (lr + lf)) *
               (pow(lf, 2) * csf * (g * lr - u1 * h) + pow(lr, 2) * csr * (g * lf + u1 * h)) * x[5] +
           mu * mass / (inertia * (lr + lf)) * (lr * csr * (g * lf + u1 * h) - lf * csf * (g * lr - u1 * h)) * x[6] +
           mu * mass / (inertia * (lr + lf)) * lf * csf * (g * lr - u1 * h) * x[2];
    f[6] = (mu / (pow(x[3], 2) * (lr + lf)) * (csr * (g * lf + u1 * h) * lr - csf * (g * lr - u1 * h) * lf) - 1) *
               x[5] -
           mu / (x[3] * (lr + lf)) * (csr * (g * lf + u1 * h) + csf * (g * lr - u1 * h)) * x[6] +
           mu / (x[3] * (lr + lf)) * (csf * (g * lr - u1 * h)) * x[2];
}

static void publish(Model *m) {
    double f[7];
    const double *x = m->x;
    rhs(m, x, f);
    double v = x[3], yaw = x[4], r = x[5], beta = x[6];
    m->out[0] = x[0] - P_B * cos(yaw);
    m->out[1] = x[1] - P_B * sin(yaw);
    m->out[2] = yaw;
    m->out[3] = v * cos(beta);
    m->out[4] = v * sin(beta) - P_B * r;
    m->out[5] = r;
    m->out[6] = x[2];
    m->out[7] = f[3] * sin(beta) + v * (r + f[6]) * cos(beta) - P_B * f[5];
}

static void step(Model *m, double duration) {
    int n = (int)ceil(duration / STEP_S - 1e-9);
    if (n < 1) n = 1;
    double h = duration / n, k1[7], k2[7], k3[7], k4[7], y[7];
    for (int s = 0; s < n; s++) {
        rhs(m, m->x, k1);
        for (int i = 0; i < 7; i++) y[i] = m->x[i] + 0.5 * h * k1[i];
        rhs(m, y, k2);
        for (int i = 0; i < 7; i++) y[i] = m->x[i] + 0.5 * h * k2[i];
        rhs(m, y, k3);
        for (int i = 0; i < 7; i++) y[i] = m->x[i] + h * k3[i];
        rhs(m, y, k4);
        for (int i = 0; i < 7; i++) m->x[i] = m->x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        if (m->x[3] < 0.0) m->x[3] = 0.0;
    }
}

static void start(Model *m) {
    memset(m->x, 0, sizeof m->x);
    m->x[0] = P_B;
    m->x[3] = m->v0;
    publish(m);
}

static double *variable(Model *m, fmi2ValueReference vr) {
    if (vr == VR_DELTA_CMD) return &m->delta_cmd;
    if (vr == VR_ACCEL_CMD) return &m->accel_cmd;
    if (vr == VR_V0) return &m->v0;
    if (vr < N_VR) return &m->out[vr - VR_FIRST_OUT];
    return NULL;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[]) { return fmi2OK; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean logging) {
    if (type != fmi2CoSimulation) return NULL;
    Model *m = calloc(1, sizeof(Model));
    if (m) m->v0 = 10.0;
    return m;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0, fmi2Boolean sd, fmi2Real t1) {
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    start((Model *)c);
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) {
    Model *m = (Model *)c;
    memset(m, 0, sizeof(Model));
    m->v0 = 10.0;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    for (size_t i = 0; i < n; i++) {
        double *v = variable((Model *)c, vr[i]);
        if (!v) return fmi2Error;
        value[i] = *v;
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= VR_FIRST_OUT) return fmi2Error;
        *variable((Model *)c, vr[i]) = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_set_prior) {
    Model *m = (Model *)c;
    step(m, h);
    publish(m);
    return fmi2OK;
}

/* What this FMU does not offer: refused. */
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) { return fmi2Error; }
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) { return fmi2Error; }
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) { return fmi2Error; }
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) { return fmi2Error; }
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) { return fmi2Error; }
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) { return fmi2Error; }
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) { return fmi2Error; }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) { return fmi2Error; }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) { return fmi2Error; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real dz[]) {
    return fmi2Error;
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    return fmi2Error;
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) {
    return fmi2Error;
}
fmi2Status fmi2CancelStep(fmi2Component c) { return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) { return fmi2Error; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) { return fmi2Error; }
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) { return fmi2Error; }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) { return fmi2Error; }
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) { return fmi2Error; }
