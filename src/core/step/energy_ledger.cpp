#include "core/step/energy_ledger.hpp"

#include "core/shape/disc.hpp"

namespace dem2d {

double mechanical_energy(const ParticleStore& p, std::size_t k, Vec2 gravity) {
  return 0.5 * p.mass[k] * norm2(p.vel[k]) + rotational_energy(p, k) -
         p.mass[k] * dot(gravity, p.pos[k]);
}

}  // namespace dem2d
