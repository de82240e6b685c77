#include "craneassist/studies/energy_experiment.hpp"

#include <cstdio>
#include <ostream>

#include "craneassist/control/trajectory_runner.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace craneassist::studies {
namespace {

struct NamedPlan {
  std::string method;
  StartExtension start;
  planner::Plan plan;
};

void say(const EnergyExperimentOptions& o, const std::string& text) {
  if (o.progress) o.progress(text);
}

}  // namespace

std::vector<EnergyRun> run_energy_experiment(const config::CraneConfig& config,
                                             const EnergyExperimentOptions& options) {
  std::vector<EnergyRun> runs;
  const auto& model = config.model;
  for (const auto& file : options.paths) {
    const auto path = input::PrescribedPath::load_file(file);
    const std::string name = file.stem().string();
    const auto samples = sample_path(path, options.dt_s);

    planner::StageModelOptions ls_options, cp_options;
    ls_options.cost = planner::PlanCost::kLoadSensing;
    cp_options.cost = planner::PlanCost::kConstantPressure;
    cp_options.cp_supply_pressure_pa = options.cp_supply_pressure_pa;
    if (config.control.activation_speed_m_s > 0.0) {
      ls_options.at_rest_speed_m_s = cp_options.at_rest_speed_m_s =
          config.control.activation_speed_m_s;
    }
    const planner::StageModel ls_model(model, samples, ls_options);
    const planner::StageModel cp_model(model, samples, cp_options);

    std::vector<NamedPlan> plans;
    for (StartExtension start : {StartExtension::kShortest, StartExtension::kMiddle}) {
      const double c0 = start_extension(ls_model, start);
      for (const char* method : {"pinv-joint", "pinv-actuator", "min-flow", "min-ls-power"}) {
        plans.push_back({method, start, make_plan(ls_model, method, c0, options.dp)});
      }
    }
    for (auto cost : {planner::PlanCost::kLoadSensing, planner::PlanCost::kConstantPressure,
                      planner::PlanCost::kActuatorEnergy, planner::PlanCost::kExtension}) {
      planner::StageModelOptions o = cp_options;
      o.cost = cost;
      const planner::StageModel stages(model, samples, o);
      say(options, name + ": DP (" + planner::to_string(cost) + ") backward phase");
      const planner::DpSolution solution(stages, options.dp);
      for (StartExtension start : {StartExtension::kShortest, StartExtension::kMiddle}) {
        const double c0 = start_extension(ls_model, start);
        plans.push_back(
            {std::string("dp-") + planner::to_string(cost), start, solution.forward(c0)});
      }
    }

    say(options, name + ": simulating " + std::to_string(plans.size()) + " plans x 2 systems");
    for (const auto& p : plans) {
      const auto traj = to_joint_trajectory(p.plan, file.string());
      for (auto mode : {dynamics::PumpMode::kLoadSensing, dynamics::PumpMode::kConstantPressure}) {
        config::CraneConfig cfg = config;
        cfg.model.pump.mode = mode;
        if (mode == dynamics::PumpMode::kConstantPressure) {
          cfg.model.pump.supply_pressure_pa = options.cp_supply_pressure_pa;
        }
        sim_backend::SimSettings settings = offline::sim_settings(cfg);
        settings.q_initial = traj.q(0);
        sim_backend::SimBackend machine(cfg.model, settings);
        const auto summary = control::run_trajectory(cfg, traj, machine, {}, nullptr);
        planner::Plan judged = p.plan;
        planner::evaluate_plan(mode == dynamics::PumpMode::kLoadSensing ? ls_model : cp_model,
                               judged);
        EnergyRun run;
        run.path = name;
        run.start = to_string(p.start);
        run.method = p.method;
        run.system = mode == dynamics::PumpMode::kLoadSensing ? "ls" : "cp";
        run.energy_j = summary.energy_j;
        run.model_energy_j = judged.total_cost;
        run.max_tip_error_m = summary.max_tip_error_m;
        run.rms_tip_error_m = summary.rms_tip_error_m;
        run.peak_power_w = summary.peak_power_w;
        run.penalised_stages = p.plan.penalised_stages;
        run.pump_saturated_cycles = summary.pump_saturated_cycles;
        run.plan_time_s = p.plan.backward_s + p.plan.forward_s;
        runs.push_back(run);
      }
    }
  }
  return runs;
}

void write_energy_csv(std::ostream& out, const std::vector<EnergyRun>& runs) {
  out << "path,start,method,system,energy_j,model_energy_j,max_tip_error_m,rms_tip_error_m,"
         "peak_power_w,penalised_stages,pump_saturated_cycles,plan_time_s\n";
  char line[512];
  for (const auto& r : runs) {
    std::snprintf(line, sizeof line, "%s,%s,%s,%s,%.1f,%.1f,%.5f,%.5f,%.1f,%d,%ld,%.3f\n",
                  r.path.c_str(), r.start.c_str(), r.method.c_str(), r.system.c_str(), r.energy_j,
                  r.model_energy_j, r.max_tip_error_m, r.rms_tip_error_m, r.peak_power_w,
                  r.penalised_stages, r.pump_saturated_cycles, r.plan_time_s);
    out << line;
  }
}

}  // namespace craneassist::studies
