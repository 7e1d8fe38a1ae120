// Plain C++ all-pairs loop: the reference program for bench-sph's speed ratios (issue 15).
//
// What it is: the `seed` preset's dam break (shared/SOLVER.md, Müller, Charypar & Gross 2003
// as the seed paper's Haskell program evaluates it), written the way the C++ original
// (cerrno/mueller-sph, src/main.cpp) is written: one std::vector of particle structs and plain
// O(N^2) loops. As in bench-sph, a step is two passes: density, then forces, each particle
// moved as soon as its force is known (into a second vector, swapped in after the pass, so
// that the other particles' forces read the old positions; the original runs the update as a
// third loop, with the same bits). No SIMD intrinsics, no grid, and no threads unless it is
// built with -fopenmp: then each pass's loop over particles is `omp parallel for schedule(static)`,
// the OpenMP team the strategies are measured against (a particle's sums do not depend on
// how the particles are split, so the bits and the checksum are the same). Speed figures of
// bench-sph are reported as ratios to this program's time, measured in the same run
// (scripts/speed-bench.sh).
//
// It computes bit for bit what `bench-sph simulate --strategy seq` (all-pairs, seed preset)
// computes: the same initial state (SplitMix64 jitter, solver/src/models/mueller/scene.rs), the
// same constants and operation order (solver/src/models/preset.rs, models/mueller/params.rs,
// models/mueller/passes.rs) and the same checksum (FNV-1a 64 over the little-endian bits of x,
// y, vx, vy per particle, solver/src/checksum.rs).
// It must be compiled without contracting a*b+c into fused multiply-adds:
//
//   g++ -O2 -ffp-contract=off -std=c++17 -o mueller benches/plain-loop/mueller.cpp
//   ./mueller [N [STEPS [SEED]]]          # defaults: 1000 1000 2019
//   g++ -O2 -ffp-contract=off -std=c++17 -fopenmp -o mueller-omp benches/plain-loop/mueller.cpp
//   OMP_NUM_THREADS=2 ./mueller-omp        # the OpenMP team on 2 threads
//
// Output, one line of JSON: {"n":..,"steps":..,"wall_s":..,"checksum":"<16 hex>"}, where
// wall_s times the step loop only (std::chrono::steady_clock), not setup or the checksum.
// For N above the layout's 1406 particles the dam grows as bench-sph's does (columns added,
// the tank 32 px wider per added column), so the program runs for any N, but the ratios are
// defined at N = 1000.

#include <chrono>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

// ---- Constants of the seed preset (src/sph/params.rs, computed in the same order) ----
const double PI = 3.14159265358979323846;  // f64::consts::PI
const double H = 16.0;                     // kernel radius
const double H6 = H * H * H * H * H * H;
const double H9 = H6 * H * H * H;
const double HSQ = H * H;
const double MASS = 65.0;
const double VISC = 250.0;
const double REST_DENS = 1000.0;
const double GAS_CONST = 2000.0;
const double POLY6 = 315.0 / (65.0 * PI * H9);
const double SPIKY_GRAD = -45.0 / (PI * H6);
const double VISC_LAP = 45.0 / (PI * H6);
const double MASS_POLY6 = MASS * POLY6;  // premultiplied, as bench-sph does
const double VISC_MASS = VISC * MASS;    // premultiplied, as bench-sph does
const double GX = 0.0;
const double GY = 12000.0 * -9.8;  // = -117600.00000000001455, not -117600
const double DT = 0.0009;
const double EPS = H;  // wall margin
const double BOUND_DAMPING = -1.0;

// ---- Layout of the seed dam (src/scene/dam_break.rs) ----
const double X0 = 16.0;
const double Y0 = 300.0;
const std::size_t ROWS = 37;
const std::size_t BASE_COLUMNS = 38;
const double SPACING = 16.0;
const double BASE_WIDTH = 1200.0;
const double BASE_HEIGHT = 900.0;

struct Particle {
    double x, y;    // position
    double vx, vy;  // velocity
    double fx, fy;  // force
    double rho, p;  // density, pressure
};

// SplitMix64 (src/scene/splitmix.rs).
struct SplitMix64 {
    std::uint64_t state;
    std::uint64_t next_u64() {
        state += 0x9e3779b97f4a7c15ULL;
        std::uint64_t z = state;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    double next_f64() {
        return static_cast<double>(next_u64() >> 11) *
               (1.0 / static_cast<double>(std::uint64_t(1) << 53));
    }
};

std::size_t columns_for(std::size_t n) {
    return n <= ROWS * BASE_COLUMNS ? BASE_COLUMNS : (n + ROWS - 1) / ROWS;
}

std::vector<Particle> init_dam(std::size_t n, std::uint64_t seed) {
    const std::size_t columns = columns_for(n);
    SplitMix64 rng{seed};
    std::vector<Particle> ps(n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t row = k / columns, col = k % columns;
        Particle& a = ps[k];
        a.x = (X0 + SPACING * static_cast<double>(col)) + rng.next_f64();
        a.y = Y0 + SPACING * static_cast<double>(row);
        a.vx = a.vy = a.fx = a.fy = a.rho = a.p = 0.0;
    }
    return ps;
}

void compute_density_pressure(std::vector<Particle>& ps) {
    const std::size_t n = ps.size();
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
        Particle& pi = ps[i];
        double rho = 0.0;
        for (std::size_t j = 0; j < n; ++j) {  // the self term j = i is included
            const Particle& pj = ps[j];
            const double dx = pj.x - pi.x;
            const double dy = pj.y - pi.y;
            const double r2 = dx * dx + dy * dy;
            if (r2 < HSQ) {
                const double u = HSQ - r2;
                rho += MASS_POLY6 * ((u * u) * u);
            }
        }
        pi.rho = rho;
        pi.p = GAS_CONST * (rho - REST_DENS);
    }
}

// Particle `a`'s own update from its force and density, then the walls.
void move(Particle& a, double width, double height) {
    // Symplectic Euler, the seed preset's grouping: v + DT * (f / rho).
    a.vx = a.vx + DT * (a.fx / a.rho);
    a.vy = a.vy + DT * (a.fy / a.rho);
    a.x = a.x + DT * a.vx;
    a.y = a.y + DT * a.vy;
    if (a.x - EPS < 0.0) {
        a.vx *= BOUND_DAMPING;
        a.x = EPS;
    }
    if (a.x + EPS > width) {
        a.vx *= BOUND_DAMPING;
        a.x = width - EPS;
    }
    if (a.y - EPS < 0.0) {
        a.vy *= BOUND_DAMPING;
        a.y = EPS;
    }
    if (a.y + EPS > height) {
        a.vy *= BOUND_DAMPING;
        a.y = height - EPS;
    }
}

// Forces from `ps`, then each particle moved: the results go to `next` (same size).
void forces_and_moves(const std::vector<Particle>& ps, std::vector<Particle>& next,
                      double width, double height) {
    const std::size_t n = ps.size();
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
        const Particle& pi = ps[i];
        double fpress_x = 0.0, fpress_y = 0.0;
        double fvisc_x = 0.0, fvisc_y = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            if (j == i) continue;
            const Particle& pj = ps[j];
            const double dx = pj.x - pi.x;
            const double dy = pj.y - pi.y;
            const double r = std::sqrt(dx * dx + dy * dy);
            if (r < H) {
                const double hr = H - r;
                // Two particles at the same point: no pressure direction, viscosity still acts.
                if (r > 0.0) {
                    const double pp = pi.p + pj.p;
                    const double rho2 = 2.0 * pj.rho;
                    const double k = hr * hr;
                    fpress_x += (((((-dx) / r) * MASS) * pp) / rho2) * SPIKY_GRAD * k;
                    fpress_y += (((((-dy) / r) * MASS) * pp) / rho2) * SPIKY_GRAD * k;
                }
                fvisc_x += (((VISC_MASS * (pj.vx - pi.vx)) / pj.rho) * VISC_LAP) * hr;
                fvisc_y += (((VISC_MASS * (pj.vy - pi.vy)) / pj.rho) * VISC_LAP) * hr;
            }
        }
        Particle& a = next[i];
        a = pi;
        a.fx = (fpress_x + fvisc_x) + GX * pi.rho;
        a.fy = (fpress_y + fvisc_y) + GY * pi.rho;
        move(a, width, height);
    }
}

// FNV-1a 64 over the little-endian bytes of the f64 bits of x, y, vx, vy (src/checksum.rs).
std::uint64_t checksum(const std::vector<Particle>& ps) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (const Particle& a : ps) {
        const double v[4] = {a.x, a.y, a.vx, a.vy};
        for (double d : v) {
            std::uint64_t bits;
            std::memcpy(&bits, &d, sizeof bits);
            for (int b = 0; b < 8; ++b) {
                h ^= (bits >> (8 * b)) & 0xffu;
                h *= 0x00000100000001b3ULL;
            }
        }
    }
    return h;
}

bool parse_u64(const char* s, std::uint64_t& out) {
    if (s == nullptr || *s == '\0' || *s == '-' || *s == '+') return false;
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(s, &end, 10);
    if (errno != 0 || *end != '\0') return false;
    out = v;
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    std::uint64_t n = 1000, steps = 1000, seed = 2019;
    if (argc > 4 || (argc > 1 && !parse_u64(argv[1], n)) ||
        (argc > 2 && !parse_u64(argv[2], steps)) || (argc > 3 && !parse_u64(argv[3], seed)) ||
        n == 0 || n > 100000000) {
        std::fprintf(stderr,
                     "Usage: %s [N [STEPS [SEED]]]  (N in 1..=100000000; defaults 1000 1000 "
                     "2019)\n",
                     argv[0]);
        return 2;
    }

    const std::size_t columns = columns_for(n);
    const double width = BASE_WIDTH + 2.0 * SPACING * static_cast<double>(columns - BASE_COLUMNS);
    const double height = BASE_HEIGHT;
    std::vector<Particle> ps = init_dam(n, seed);
    std::vector<Particle> next = ps;

    const auto t0 = std::chrono::steady_clock::now();
    for (std::uint64_t s = 0; s < steps; ++s) {
        compute_density_pressure(ps);
        forces_and_moves(ps, next, width, height);
        ps.swap(next);
    }
    const auto t1 = std::chrono::steady_clock::now();
    const double wall_s = std::chrono::duration<double>(t1 - t0).count();

    std::printf("{\"n\":%" PRIu64 ",\"steps\":%" PRIu64 ",\"wall_s\":%.9f,\"checksum\":\"%016" PRIx64
                "\"}\n",
                n, steps, wall_s, checksum(ps));
    return 0;
}
