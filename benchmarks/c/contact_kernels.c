/* Plain C reference of the two batched contact kernels of frictionrules.contact._kernels.
 * Same arithmetic, same row-major layout: displacements and forces (n, 3), the rest (n,).
 * Inputs: elastic e and plastic p displacements, slip kappa, increments du.
 * Compiled by benchmarks/contact_update.py with gcc -O3 and called through ctypes.
 * Status codes: 0 elastic, 1 plastic, 2 open. */
#include <math.h>
#include <stdint.h>

#define OUTS double *out_e, double *out_p, double *out_kappa, double *out_force, \
             double *out_dlam, int8_t *out_status, double *out_diss

static inline void set_open(long i, double e0, double e1, double e2, const double *p, const double *kappa, OUTS)
{
    const long j = 3 * i;
    out_e[j] = 0.0; out_e[j + 1] = 0.0; out_e[j + 2] = e2;
    out_p[j] = p[j] + e0; out_p[j + 1] = p[j + 1] + e1; out_p[j + 2] = p[j + 2];
    out_force[j] = 0.0; out_force[j + 1] = 0.0; out_force[j + 2] = 0.0;
    out_kappa[i] = kappa[i]; out_dlam[i] = 0.0; out_status[i] = 2; out_diss[i] = 0.0;
}

static inline void set_elastic(long i, double e0, double e1, double e2, double T1, double T2, double N,
                               const double *p, const double *kappa, OUTS)
{
    const long j = 3 * i;
    out_e[j] = e0; out_e[j + 1] = e1; out_e[j + 2] = e2;
    out_p[j] = p[j]; out_p[j + 1] = p[j + 1]; out_p[j + 2] = p[j + 2];
    out_force[j] = T1; out_force[j + 1] = T2; out_force[j + 2] = N;
    out_kappa[i] = kappa[i]; out_dlam[i] = 0.0; out_status[i] = 0; out_diss[i] = 0.0;
}

static inline void set_plastic(long i, double e0, double e1, double e2, double T1, double T2, double N,
                               double kt, double kn, double dl, double dkappa,
                               const double *p, const double *kappa, OUTS)
{
    const long j = 3 * i;
    double f0 = T1 / kt, f1 = T2 / kt, f2 = -N / kn;
    double d0 = e0 - f0, d1 = e1 - f1, d2 = e2 - f2;
    out_e[j] = f0; out_e[j + 1] = f1; out_e[j + 2] = f2;
    out_p[j] = p[j] + d0; out_p[j + 1] = p[j + 1] + d1; out_p[j + 2] = p[j + 2] + d2;
    out_force[j] = T1; out_force[j + 1] = T2; out_force[j + 2] = N;
    out_kappa[i] = kappa[i] + dkappa; out_dlam[i] = dl; out_status[i] = 1;
    out_diss[i] = T1 * d0 + T2 * d1 - N * d2;
}

void coulomb_update(long n, const double *e, const double *p, const double *kappa, const double *du,
                    double kt, double kn, double mu, int dilatant, OUTS)
{
    for (long i = 0; i < n; ++i) {
        const long j = 3 * i;
        double e0 = e[j] + du[j], e1 = e[j + 1] + du[j + 1], e2 = e[j + 2] + du[j + 2];
        double T1 = kt * e0, T2 = kt * e1, N = -kn * e2;
        if (N <= 0.0) {
            set_open(i, e0, e1, e2, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss);
            continue;
        }
        double r = sqrt(T1 * T1 + T2 * T2);
        double f = r - mu * N;
        if (f <= 0.0) {
            set_elastic(i, e0, e1, e2, T1, T2, N, p, kappa,
                        out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss);
            continue;
        }
        double dl;
        if (dilatant) {
            dl = f / (kt + kn * mu * mu);
            N = N + kn * mu * dl;
        } else {
            dl = f / kt;
        }
        double c = mu * N / r;
        set_plastic(i, e0, e1, e2, T1 * c, T2 * c, N, kt, kn, dl, dl, p, kappa,
                    out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss);
    }
}

void elliptic_update(long n, const double *e, const double *p, const double *kappa, const double *du,
                     double kt, double kn, double mu_x, double mu_y, double angle, OUTS)
{
    const double c = cos(angle), s = sin(angle);
    for (long i = 0; i < n; ++i) {
        const long j = 3 * i;
        double e0 = e[j] + du[j], e1 = e[j + 1] + du[j + 1], e2 = e[j + 2] + du[j + 2];
        double T1 = kt * e0, T2 = kt * e1, N = -kn * e2;
        if (N <= 0.0) {
            set_open(i, e0, e1, e2, p, kappa, out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss);
            continue;
        }
        double a1 = c * T1 + s * T2, a2 = -s * T1 + c * T2;
        double rho = sqrt((a1 / mu_x) * (a1 / mu_x) + (a2 / mu_y) * (a2 / mu_y));
        if (rho <= N) {
            set_elastic(i, e0, e1, e2, T1, T2, N, p, kappa,
                        out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss);
            continue;
        }
        double N2 = N * N, x = 0.0;
        for (int it = 0; it < 100; ++it) {
            double d1 = mu_x + x / mu_x, d2 = mu_y + x / mu_y;
            double q1 = a1 * a1 / (d1 * d1), q2 = a2 * a2 / (d2 * d2);
            double phi = q1 + q2 - N2;
            double dphi = -2.0 * (q1 / (d1 * mu_x) + q2 / (d2 * mu_y));
            double dx = -phi / dphi;
            x += dx;
            if (dx <= 1e-15 * x) break;
        }
        double b1 = a1 / (1.0 + x / (mu_x * mu_x)), b2 = a2 / (1.0 + x / (mu_y * mu_y));
        double dl = x * N / kt;
        double g1 = b1 / (mu_x * mu_x * N), g2 = b2 / (mu_y * mu_y * N);
        set_plastic(i, e0, e1, e2, c * b1 - s * b2, s * b1 + c * b2, N, kt, kn, dl, dl * sqrt(g1 * g1 + g2 * g2),
                    p, kappa, out_e, out_p, out_kappa, out_force, out_dlam, out_status, out_diss);
    }
}
