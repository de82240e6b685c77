#include "research/goal_move.hpp"

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <optional>
#include <stdexcept>
#include <utility>

#include "craneassist/planner/ptp_planner.hpp"
#include "research/goal_planning.hpp"
#include "research/ptp_command.hpp"

namespace craneassist::cli {
namespace {

class GoalMove final : public input::GoalPlanning {
 public:
  GoalMove(const config::CraneConfig& cfg, const GoalMoveOptions& options)
      : goals_(parse_goals(options.goal, options.goal_at)),
        weights_(parse_weights("--goal-weights", options.weights)),
        limits_{options.speed_m_s, cfg.scaling.acceleration_max_m_s2} {
    try {
      arm_.emplace(cfg.model, cfg.simulation.q_initial);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--input goal", cfg.model.name + ": " + e.what());
    }
    planner::PostureTableSettings table_settings;
    if (!options.grid.empty()) {
      table_settings.spacing_m = parse_grid_spacing("--goal-grid", options.grid);
      check_grid_size(*arm_, cfg.model.name, table_settings.spacing_m, "--goal-grid");
    }
    std::vector<std::pair<std::string, Eigen::Vector2d>> points;
    for (const auto& g : goals_)
      points.emplace_back(g.t_s == 0.0 && !options.goal.empty() ? "--goal" : "--goal-at", g.xz);
    table_.emplace(posture_table_for(cfg, *arm_, table_settings, options.table, points));
    planner_.emplace(*arm_, table_->table, planner::PtpSettings{});
    spdlog::info("goal planner: {} nodes, {:.0f} mm grid, posture table {}",
                 table_->table.grid().nodes(), 1000.0 * table_->table.grid().spacing_m,
                 table_->loaded ? "loaded from " + table_->file->string() : std::string("built"));
  }
  ~GoalMove() override { stop(); }

  void start(input::GoalSource& source) override {
    // Goals typed on standard input replan too (a terminal in line mode, or a pipe).
    thread_.emplace(*planner_, source, goals_, weights_, limits_, true);
    thread_->start();
  }
  void stop() override {
    if (thread_) thread_->stop();
  }
  std::vector<std::string> report() const override {
    return thread_ ? thread_->report() : std::vector<std::string>{};
  }

 private:
  std::vector<GoalAt> goals_;
  planner::PtpWeights weights_;
  TipLimits limits_;
  std::optional<planner::PlanarArm> arm_;
  std::optional<LoadedTable> table_;
  std::optional<planner::PtpPlanner> planner_;
  std::optional<GoalPlanner> thread_;
};

}  // namespace

std::unique_ptr<input::GoalPlanning> make_goal_move(const config::CraneConfig& cfg,
                                                    const GoalMoveOptions& options) {
  return std::make_unique<GoalMove>(cfg, options);
}

}  // namespace craneassist::cli
