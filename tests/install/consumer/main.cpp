// Uses the installed libraries: the reference crane's config, its simulator for one second
// with the slew valve open, and the tip position it reached.
#include <cstdio>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

int main() {
  using namespace craneassist;
  const config::CraneConfig cfg = config::default_crane_config();
  sim_backend::SimBackend sim(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
  valves::ValveCommand command;
  command.spool = dynamics::JointVector::Zero(cfg.model.dof());
  command.spool[0] = 0.8;  // slew
  valves::MachineState state;
  sim.read(state);
  const double q0 = state.q[0];
  for (int k = 0; k < 100; ++k) {
    sim.write(command);
    sim.advance(0.01);
  }
  sim.read(state);
  dynamics::KinematicsData kin;
  const Eigen::Vector3d tip = dynamics::tip_position(cfg.model, kin, state.q);
  std::printf("%s: slew moved %.3f rad, tip at %.3f %.3f %.3f m\n", cfg.model.name.c_str(),
              state.q[0] - q0, tip.x(), tip.y(), tip.z());
  return state.q[0] - q0 > 0.05 ? 0 : 1;
}
