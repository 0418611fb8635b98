// The fixed benchmark workloads of docs/benchmarks.md, built as scenes.
#pragma once

#include <cstdint>
#include <string>

#include "motes/api.h"
#include "motes/scene.h"

MOTES_API_BEGIN
namespace motes {

/// W1 "settle": NX x NY x NZ free spheres (d = 0.01 m, density 2500 kg/m^3) on a simple-cubic
/// lattice of spacing 1.1 d with a seeded random offset in [-0.01 d, 0.01 d] per coordinate,
/// falling into a box open at the top (floor y = 0, walls x = 0, x = (NX+1) s, z = 0,
/// z = (NZ+1) s); k = 2000 N/m, gamma_n = 50/s, gamma_t = 25/s, mu = 0.5 (LAMMPS gran/hooke);
/// dt = 2e-5 s. Sphere mass = density * pi/6 d^3, as in LAMMPS.
Scene settle_workload(int nx, int ny, int nz, std::uint64_t seed = 12345);

/// W1 from the state LAMMPS wrote after settling (write_data of peers' in.make_settled: atom
/// style sphere, velocities included): the same spheres, walls at x = xhi and z = zhi, the same
/// contact law. Lets both codes run the dense phase from one identical state.
Result<Scene> settle_workload_from_lammps(const std::string& path);

/// NX x NY x NZ for a W1 size in docs/benchmarks.md (16,384 ... 268,435,456); false if not one.
bool settle_dimensions(std::uint64_t particles, int& nx, int& ny, int& nz);

/// W2 "dominoes": `count` dominoes of 1 x 3 x 5 particles (d = 0.01 m) in `rows` parallel rows
/// on a floor, pitch 0.6 x domino height along a row; the first of each row is tipped.
Scene dominoes_workload(int count, int rows);

/// "impulse-dominoes": W2's dominoes with impulse contacts (settings.contact_model Impulses, 16
/// iterations; restitution 0.3, friction 0.5) and dt = 2e-4 s, ten times W2's: impulses have no
/// stiffness to resolve, only the travel per step to keep below the contact margin.
Scene impulse_dominoes_workload(int count, int rows);

/// W3 "cloth": a side x side cloth (d = 0.01 m particles, spacing d; structural, shear and bend
/// links; 8 relaxation sweeps; self-collision on) held at the two corners of one edge, starting
/// flat at y = 0.1 m + side d so that it swings down and folds without reaching the floor at
/// y = 0 in the first second; k = 2000 N/m, gamma_n = 500/s, dt = 1e-4 s, link damping 1/s.
/// side: 2 to 1024.
Scene cloth_workload(int side);

/// W4 "soft": `count` soft cubes of 7 x 7 x 8 = 392 particles (d = 0.01 m; linear goals, beta 0.3,
/// 20 Hz, internal damping 40/s) in a square grid, 0.12 m apart, falling from 0.06 m above the
/// floor so that they land within the first 0.1 s; k = 2000 N/m, gamma_n = 500/s, dt = 1e-4 s.
/// count: 1 to 100,000.
Scene soft_workload(int count);
/// W5 "fluid": a dam break of about `particles` liquid particles (d = 0.01 m, water, position-based
/// fluids at the settled defaults: 16 substeps of 1/60 s, 2 sweeps; docs/fluids.md): a column
/// a x 2 a x a (n^2 = 2, a = cbrt(particles / 2) particles) at one end of a tank 4 a long and a
/// wide, with four rigid 4 cm cubes of 700 kg/m^3 on the floor 1.5 a to 3 a along it.
/// particles: 16 to 100,000,000.
Scene fluid_workload(std::uint64_t particles);

}  // namespace motes
MOTES_API_END
