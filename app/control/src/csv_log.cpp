#include "craneassist/control/csv_log.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace craneassist::control {

std::string CsvLog::header(int dof, bool base) {
  std::string h =
      "t,cmd_vx,cmd_vy,cmd_vz,ref_vx,ref_vy,ref_vz,tip_x,tip_y,tip_z,tip_vx,tip_vy,tip_vz";
  for (int i = 1; i <= dof; ++i) h += ",q" + std::to_string(i);
  for (int i = 1; i <= dof; ++i) h += ",q" + std::to_string(i) + "_ref";
  h += ",pump_flow_m3s,pump_pressure_pa,pump_power_w,energy_j,active_limit,scale,flow_demand_m3s,"
       "pump_limit";
  h += ",s,sdot,sddot,sdddot,sddot_min,sddot_max,tip_error_m,ref_power_w";
  h += ",avail_speed_m_s,avail_speed_resolved_m_s,polytope_volume_m3s3";
  for (int i = 1; i <= dof; ++i) h += ",spool" + std::to_string(i);
  for (int i = 1; i <= dof; ++i) h += ",p_load" + std::to_string(i) + "_pa";
  h += ",load_kg,payload_estimate_kg,load_moment_ratio,status";
  h += ",swing_deg,swing_radial_deg,swing_tangential_deg";
  if (base) {
    h += ",base_x,base_y,base_phi,base_v,base_omega,base_v_cmd,base_omega_cmd,base_flow_fl_m3s,"
         "base_flow_fr_m3s,base_flow_rl_m3s,base_flow_rr_m3s,base_flow_sum_m3s,base_flow_max_m3s";
  }
  return h;
}

CsvLog::CsvLog(const std::filesystem::path& path, int dof, std::size_t capacity_rows, bool base)
    : path_(path), dof_(dof), base_(base), ring_(capacity_rows) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    throw std::runtime_error(path.string() + ": cannot open the log file for writing");
  }
  std::fprintf(file_, "%s\n", header(dof, base).c_str());
  writer_ = std::thread([this] { writer_loop(); });
}

CsvLog::~CsvLog() {
  close();
}

bool CsvLog::push(const LogRow& row) noexcept {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  const std::size_t next = (head + 1) % ring_.size();
  if (next == tail_.load(std::memory_order_acquire)) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  ring_[head] = row;
  head_.store(next, std::memory_order_release);
  return true;
}

void CsvLog::write_row(const LogRow& r) {
  std::fprintf(file_, "%.4f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6f,%.6f,%.6f,%.6g,%.6g,%.6g", r.t,
               r.cmd[0], r.cmd[1], r.cmd[2], r.ref_v[0], r.ref_v[1], r.ref_v[2], r.tip[0], r.tip[1],
               r.tip[2], r.tip_v[0], r.tip_v[1], r.tip_v[2]);
  for (int i = 0; i < dof_; ++i) std::fprintf(file_, ",%.7f", r.q[static_cast<std::size_t>(i)]);
  for (int i = 0; i < dof_; ++i) std::fprintf(file_, ",%.7f", r.q_ref[static_cast<std::size_t>(i)]);
  std::fprintf(file_, ",%.6g,%.6g,%.6g,%.6g,%s,%.6g,%.6g,%s", r.pump_flow_m3s, r.pump_pressure_pa,
               r.pump_power_w, r.energy_j, r.active_limit, r.scale, r.flow_demand_m3s,
               r.pump_limit);
  std::fprintf(file_, ",%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", r.s, r.sdot, r.sddot, r.sdddot,
               r.sddot_min, r.sddot_max, r.tip_error_m, r.ref_power_w);
  std::fprintf(file_, ",%.6g,%.6g,%.6g", r.avail_speed_m_s, r.avail_speed_resolved_m_s,
               r.polytope_volume_m3s3);
  for (int i = 0; i < dof_; ++i) std::fprintf(file_, ",%.5f", r.spool[static_cast<std::size_t>(i)]);
  for (int i = 0; i < dof_; ++i) {
    std::fprintf(file_, ",%.6g", r.load_pressure[static_cast<std::size_t>(i)]);
  }
  // The simulator's truth is empty on a machine (NaN).
  if (std::isfinite(r.load_kg)) {
    std::fprintf(file_, ",%.6g", r.load_kg);
  } else {
    std::fputc(',', file_);
  }
  std::fprintf(file_, ",%.6g,%.6g,%s", r.payload_estimate_kg, r.load_moment_ratio, r.status);
  // Empty where nothing measures the swing (a rigid tip, a machine without a swing sensor).
  for (const double rad : {r.swing_rad, r.swing_radial_rad, r.swing_tangential_rad}) {
    if (std::isfinite(rad)) {
      std::fprintf(file_, ",%.4f", rad * 180.0 / M_PI);
    } else {
      std::fputc(',', file_);
    }
  }
  if (base_) {
    std::fprintf(file_, ",%.6f,%.6f,%.7f,%.6g,%.6g,%.6g,%.6g", r.base_pose[0], r.base_pose[1],
                 r.base_pose[2], r.base_velocity[0], r.base_velocity[1], r.base_command[0],
                 r.base_command[1]);
    for (double q : r.base_motor_flow) std::fprintf(file_, ",%.6g", q);
    std::fprintf(file_, ",%.6g,%.6g", r.base_flow_sum_m3s, r.base_flow_max_m3s);
  }
  std::fputc('\n', file_);
  written_.fetch_add(1, std::memory_order_relaxed);
}

void CsvLog::writer_loop() {
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t head = head_.load(std::memory_order_acquire);
    while (tail != head) {
      write_row(ring_[tail]);
      tail = (tail + 1) % ring_.size();
      tail_.store(tail, std::memory_order_release);
    }
    if (stopping) return;  // everything pushed before stop_ was set has been written
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::size_t CsvLog::close() {
  if (writer_.joinable()) {
    stop_.store(true, std::memory_order_release);
    writer_.join();
  }
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  return dropped_.load();
}

}  // namespace craneassist::control
