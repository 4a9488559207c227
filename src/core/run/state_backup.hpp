// StateBackup: the last known good state of this rank's owned particles, so that a run that
// blows up can still write a finite snapshot (docs/architecture.md, exit 3).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/shape/particles.hpp"

namespace dem2d {

class StateBackup {
 public:
  void save(const ParticleStore& p, double time, std::int64_t step) {
    const std::size_t n = p.n_owned();
    pos_.assign(p.pos.data(), p.pos.data() + n);
    vel_.assign(p.vel.data(), p.vel.data() + n);
    theta_.assign(p.theta.data(), p.theta.data() + n);
    omega_.assign(p.omega.data(), p.omega.data() + n);
    id_.assign(p.id.data(), p.id.data() + n);
    time_ = time;
    step_ = step;
  }
  // Put the saved state back if this rank still owns the same particles (a rebuild since the
  // save may have moved them); returns false when it could not.
  bool restore(ParticleStore& p, double& time, std::int64_t& step) const {
    const std::size_t n = p.n_owned();
    if (pos_.size() != n || !std::equal(id_.begin(), id_.end(), p.id.data())) return false;
    std::copy(pos_.begin(), pos_.end(), p.pos.data());
    std::copy(vel_.begin(), vel_.end(), p.vel.data());
    std::copy(theta_.begin(), theta_.end(), p.theta.data());
    std::copy(omega_.begin(), omega_.end(), p.omega.data());
    time = time_;
    step = step_;
    return true;
  }

 private:
  std::vector<Vec2> pos_, vel_;
  std::vector<double> theta_, omega_;
  std::vector<std::int64_t> id_;
  double time_ = 0.0;
  std::int64_t step_ = 0;
};

}  // namespace dem2d
