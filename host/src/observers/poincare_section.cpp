#include "nonsep/host/observers/poincare_section.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>

#include "nonsep/core/base/error.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

PoincareSectionObserver::PoincareSectionObserver(const std::filesystem::path& path, const PoincareSection& section,
                                                 const IntegratorSpec& integrator, const TimeGrid& time,
                                                 std::size_t dimension, std::size_t trajectories, bool energy,
                                                 bool resuming)
    : plane_(section.normal, section.offset),
      direction_(section.direction),
      max_crossings_(section.max_crossings),
      integrator_(integrator),
      time_(time),
      dimension_(dimension),
      energy_(energy),
      path_(path),
      previous_q_(trajectories * dimension),
      previous_p_(trajectories * dimension),
      counts_(trajectories, 0) {
  std::string header = "trajectory,crossing,step,t";
  for (const char* name : {"q", "p"})
    for (std::size_t i = 0; i < dimension; ++i) header += "," + std::string(name) + std::to_string(i);
  header += ",H";
  if (!resuming) file_.emplace(path, header);
}

void PoincareSectionObserver::prepare_blocks(std::size_t blocks) {
  blocks_.clear();
  for (std::size_t b = 0; b < blocks; ++b)
    blocks_.push_back(
        {PoincareCrossingLocator<Integrator>(Integrator(integrator_)), EnergyEvaluator(integrator_.form), {}, {}, {}});
}

bool PoincareSectionObserver::crosses(double before, double after) const {
  const bool up = before < 0.0 && after >= 0.0, down = before > 0.0 && after <= 0.0;
  return direction_ == CrossingDirection::up ? up : direction_ == CrossingDirection::down ? down : up || down;
}

void PoincareSectionObserver::remember(const BlockView& block) {
  const std::size_t n = dimension_;
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
    const std::size_t first = block.trajectories[slot] * n;
    std::copy_n(block.q.begin() + static_cast<std::ptrdiff_t>(slot * n), n, previous_q_.begin() + first);
    std::copy_n(block.p.begin() + static_cast<std::ptrdiff_t>(slot * n), n, previous_p_.begin() + first);
  }
}

void PoincareSectionObserver::on_step(std::uint64_t step, double, const BlockView& block) {
  BlockState& state = blocks_[block.block];
  const std::size_t n = dimension_;
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
    const std::size_t trajectory = block.trajectories[slot];
    const std::span<const double> q_before(previous_q_.data() + trajectory * n, n),
        p_before(previous_p_.data() + trajectory * n, n), q = block.q.subspan(slot * n, n),
                                                          p = block.p.subspan(slot * n, n);
    if (!crosses(plane_.distance(q_before, p_before), plane_.distance(q, p))) continue;
    Found found{step, trajectory, counts_[trajectory], 0.0, {}, {}, {}};
    try {
      state.locator.locate(*block.model, q_before, p_before, time_.time_at(step - 1), time_.dt, plane_, state.crossing);
      if (energy_) {
        double h = 0.0;
        state.energy.evaluate(*block.model, PhaseSpaceBatch::single(state.crossing.q, state.crossing.p),
                              std::span<double>(&h, 1));
        if (std::isfinite(h)) found.energy = h;
      }
    } catch (const ModelError& error) {
      if (block.retire)
        block.retire->push_back(stop_request(trajectory, TrajectoryStatus::failed,
                                             "the model failed while locating a Poincare crossing in step " +
                                                 std::to_string(step) + ": " + error.what()));
      continue;
    }
    ++counts_[trajectory];
    found.t = state.crossing.time;
    found.q = state.crossing.q;
    found.p = state.crossing.p;
    state.found.push_back(std::move(found));
    if (max_crossings_ && counts_[trajectory] == *max_crossings_ && block.retire)
      block.retire->push_back(
          stop_request(trajectory, TrajectoryStatus::completed,
                       "stopped at its " + ordinal(*max_crossings_) + " Poincare crossing (max_crossings)"));
  }
  remember(block);
}

void PoincareSectionObserver::save_block(const BlockView& block) {
  BlockState& state = blocks_[block.block];
  state.found.clear();
  state.counts_at_chunk_start.clear();
  for (std::size_t trajectory : block.trajectories) state.counts_at_chunk_start.push_back(counts_[trajectory]);
  remember(block);
}

void PoincareSectionObserver::restore_block(const BlockView& block) {
  BlockState& state = blocks_[block.block];
  state.found.clear();
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot)
    counts_[block.trajectories[slot]] = state.counts_at_chunk_start[slot];
  remember(block);
}

void PoincareSectionObserver::write(const Found& found) {
  std::string& row = file_->row();
  row += std::to_string(found.trajectory);
  row += ',';
  row += std::to_string(found.crossing);
  row += ',';
  row += std::to_string(found.step);
  row += ',';
  append_number(row, found.t);
  for (const auto* values : {&found.q, &found.p})
    for (double x : *values) {
      row += ',';
      append_number(row, x);
    }
  row += ',';
  append_csv_number(row, found.energy);
  file_->end_row();
}

void PoincareSectionObserver::after_chunk(std::uint64_t) {
  std::vector<const Found*> all;
  for (const BlockState& state : blocks_)
    for (const Found& found : state.found) all.push_back(&found);
  std::sort(all.begin(), all.end(), [](const Found* a, const Found* b) {
    return std::tie(a->step, a->trajectory) < std::tie(b->step, b->trajectory);
  });
  for (const Found* found : all) write(*found);
  for (BlockState& state : blocks_) state.found.clear();
}

std::uint64_t PoincareSectionObserver::total_crossings() const {
  return std::accumulate(counts_.begin(), counts_.end(), std::uint64_t{0});
}

nlohmann::json PoincareSectionObserver::save() {
  nlohmann::json state = csv_checkpoint_state(*file_);
  state["crossings"] = counts_;
  return state;
}

void PoincareSectionObserver::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  const nlohmann::json& counts = read.list(read.member(state, "crossings"), counts_.size(), "crossings");
  for (std::size_t i = 0; i < counts.size(); ++i) counts_[i] = read.count(counts[i], "a crossing count");
  resume_csv(file_, path_, state, [&](const std::string& what) { read.damaged(what); });
}

void PoincareSectionObserver::cells(std::size_t trajectory, std::string& row) const {
  row += ',';
  row += std::to_string(counts_[trajectory]);
}

}  // namespace nonsep::host
