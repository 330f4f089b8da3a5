#include "engine/linear/assembler.hpp"

#include "engine/linear/sparse_entry.hpp"

#include "engine/core/discrete_gradient.hpp"
#include "engine/core/stage_gradient.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace mpx {

Assembler::Assembler(const Model& model, Component::LocalForm form, int stages)
    : stages_(stages), size_(model.layout().total()) {
  const int n = size_, unknowns = stages * n;
  residual_ = Eigen::VectorXd::Zero(unknowns);
  rowScale_ = Eigen::VectorXd::Zero(unknowns);

  // pattern: the coupled pairs of each component's dofs, plus the diagonal, in every block;
  // a kinematic row (of a position) depends on velocities and not on their rates, so that off
  // its own stage's block (where only rates couple stages) it has no velocity entries, and
  // the stage system condenses as the one-stage system does
  const Layout& layout = model.layout();
  auto inBlock = [&](const Component& component, int rowStage, int columnStage, int i, int j) {
    const int row = component.dofs()[i], column = component.dofs()[j];
    return component.couples(i, j, form) && (rowStage == columnStage || layout.blockOf(row) != Block::Position ||
                                             layout.blockOf(column) != Block::Velocity);
  };
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < unknowns; ++i) entries.emplace_back(i, i, 0.0);
  for (const auto& component : model.components()) {
    const auto& dofs = component->dofs();
    if (dofs.size() > static_cast<std::size_t>(kMaxLocalDofs))
      throw std::logic_error("component '" + component->name() + "' touches more than kMaxLocalDofs dofs");
    for (int rowStage = 0; rowStage < stages; ++rowStage)
      for (int columnStage = 0; columnStage < stages; ++columnStage)
        for (int i = 0; i < static_cast<int>(dofs.size()); ++i)
          for (int j = 0; j < static_cast<int>(dofs.size()); ++j)
            if (inBlock(*component, rowStage, columnStage, i, j))
              entries.emplace_back(dofs[i] + rowStage * n, dofs[j] + columnStage * n, 0.0);
  }
  tangent_.resize(unknowns, unknowns);
  tangent_.setFromTriplets(entries.begin(), entries.end());
  tangent_.makeCompressed();

  // scatter maps: position of (row, col) of each block in the compressed column `col`
  for (const auto& component : model.components()) {
    const auto& dofs = component->dofs();
    for (int rowStage = 0; rowStage < stages; ++rowStage)
      for (int columnStage = 0; columnStage < stages; ++columnStage) {
        std::vector<std::pair<int, int>> map;
        for (int j = 0; j < static_cast<int>(dofs.size()); ++j)
          for (int i = 0; i < static_cast<int>(dofs.size()); ++i) {
            if (!inBlock(*component, rowStage, columnStage, i, j)) continue;
            map.emplace_back(static_cast<int>(i + j * dofs.size()),
                             findEntry(tangent_, dofs[i] + rowStage * n, dofs[j] + columnStage * n));
          }
        // by matrix entry (a component reaches each entry once), so that a part is a range
        std::sort(map.begin(), map.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
        scatterMap_.push_back(std::move(map));
      }
  }
  scatterParts_ = std::max(1, omp_get_max_threads());
  for (const auto& map : scatterMap_)
    for (int p = 0; p <= scatterParts_; ++p) {
      const auto start = std::lower_bound(map.begin(), map.end(), partBound(p),
                                          [](const std::pair<int, int>& pair, int e) { return pair.second < e; });
      partStart_.push_back(static_cast<int>(start - map.begin()));
    }
  // rows of the prescribed motions at every stage, to be overwritten
  const auto& prescribed = model.prescribedMotions();
  prescribedRowEntries_.assign(prescribed.size() * stages, {});
  std::vector<int> prescribedRow(unknowns, -1);
  for (std::size_t k = 0; k < prescribed.size(); ++k)
    for (int l = 0; l < stages; ++l) prescribedRow[prescribed[k].dof + l * n] = static_cast<int>(k) * stages + l;
  const int* outer = tangent_.outerIndexPtr();
  const int* inner = tangent_.innerIndexPtr();
  for (int e = 0; e < outer[unknowns]; ++e)
    if (prescribedRow[inner[e]] >= 0) prescribedRowEntries_[prescribedRow[inner[e]]].push_back(e);
  for (const PrescribedMotion& p : prescribed)
    for (int l = 0; l < stages; ++l) prescribedDiagonal_.push_back(findEntry(tangent_, p.dof + l * n, p.dof + l * n));
  // a collocation step's last stage row of a prescribed velocity or temperature holds the end
  // value, which depends on the dof at every stage
  if (stages > 1)
    for (const PrescribedMotion& p : prescribed)
      for (int m = 0; m < stages; ++m)
        prescribedEndEntries_.push_back(findEntry(tangent_, p.dof + (stages - 1) * n, p.dof + m * n));
  const auto& components = model.components();
  for (std::size_t c = 0; c < components.size(); ++c) {
    const bool together = stages > 1 && components[c]->evaluatesStagesTogether();
    if (together) together_.push_back(c);
    (components[c]->isCoupling() ? everyComponent_.couplings : everyComponent_.owners).push_back(c);
    if (!together) (components[c]->isCoupling() ? stageByStage_.couplings : stageByStage_.owners).push_back(c);
  }
  for (const auto& component : components) largest_ = std::max(largest_, component->dofs().size());
  const std::size_t slots = std::min(kBatch, components.size());
  localResidual_.assign(slots * stages * largest_, 0.0);
  localTangent_.assign(slots * largest_ * largest_, 0.0);
  localFlows_.resize(slots * stages);
  componentFlows_.resize(components.size() + 1);
  for (std::size_t b = 0; b < slots; ++b)
    locals_.push_back(
        {0, localResidual_.data() + b * stages * largest_, localTangent_.data() + b * largest_ * largest_});
}

void Assembler::clear(bool tangent) {
  residual_.setZero();
  // the tangent's values part by part, on the threads where there are enough of them
  double* values = tangent_.valuePtr();
  auto clearPart = [&](int p) { std::fill(values + partBound(p), values + partBound(p + 1), 0.0); };
  if (tangent)
    forEachPart(static_cast<int>(std::min<long long>(tangent_.nonZeros() / kEntriesPerSlot, kBatch)), clearPart);
  flows_ = Flows{};
  if (keepComponentFlows_) std::fill(componentFlows_.begin(), componentFlows_.end(), Flows{});
}

void Assembler::scatterTangents(const std::size_t* batch, int count, const Pass& pass) {
  double* values = tangent_.valuePtr();
  // part p of every slot's map, slot by slot: each entry's terms arrive in component order
  auto scatterPart = [&](int p) {
    for (int b = 0; b < count; ++b) {
      const std::size_t m = batch[b] * stages_ * stages_ + pass.block;
      const auto& map = scatterMap_[m];
      const int* start = partStart_.data() + m * (scatterParts_ + 1);
      for (int e = start[p]; e < start[p + 1]; ++e) values[map[e].second] += pass.weight * locals_[b].k[map[e].first];
    }
  };
  forEachPart(count, scatterPart);
}

void Assembler::scatterResidual(std::size_t component, const std::vector<int>& dofs, const double* r, int stage,
                                double weight) {
  const int rowOffset = stage * size_;
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    residual_[dofs[i] + rowOffset] += weight * r[i];
    if (!std::isfinite(r[i]) && firstNonFinite_.component < 0) firstNonFinite_ = {static_cast<int>(component), dofs[i]};
  }
}

void Assembler::replaceRow(std::size_t k, const PrescribedMotion& p, double value, double diagonal, double conjugate,
                           int stage, double weight) {
  const int row = p.dof + stage * size_;
  const double reaction = residual_[row];
  // a prescribed temperature's reaction is the heat it supplies, which brings entropy at that
  // temperature (`conjugate` holds it); a prescribed velocity's reaction does work
  Flows crossed;
  if (p.kind == PrescribedKind::Temperature) {
    crossed.boundaryHeat = reaction;
    crossed.boundaryEntropy = reaction / conjugate;
  } else {
    crossed.externalWork = reaction * conjugate;
  }
  flows_ += crossed * weight;
  if (keepComponentFlows_) componentFlows_.back() += crossed * weight;
  double* values = tangent_.valuePtr();
  const std::size_t slot = k * stages_ + stage;
  for (int e : prescribedRowEntries_[slot]) values[e] = 0.0;
  values[prescribedDiagonal_[slot]] = diagonal;
  residual_[row] = value;
}

void Assembler::addStages(const Model& model, Workspace& ws, StageArgs args) {
  // the rate form at the stages, or a component's own energy-consistent stage form; a residual
  // alone comes from addStagesTogether for the components that evaluate their stages together
  auto evaluate = [&](const Component& c, Workspace& w, LocalSystem& l, Flows& f) {
    if (c.stageForm() == Component::StageForm::Own)
      c.stageLocal(args, w, l, f);
    else
      c.rateLocal(args.rateArgs(), w, l, f);
  };
  // each stage row block with its own stage's columns first: that pass gives the residual
  const int columnPasses = args.tangent ? stages_ : 1;
  for (args.stage = 0; args.stage < stages_; ++args.stage)
    for (int offset = 0; offset < columnPasses; ++offset) {
      args.column = (args.stage + offset) % stages_;
      // every pass after the first meets each component at the stage values it has seen
      args.samePath = args.stage > 0 || offset > 0;
      add(model, ws,
          {args.stage * stages_ + args.column, 1.0, args.rule->weight[args.stage], offset == 0, args.tangent}, evaluate,
          args.tangent ? everyComponent_ : stageByStage_);
    }
  // a together-component's only call of a residual-only evaluation starts its path afresh
  args.samePath = false;
  if (!args.tangent) addStagesTogether(model, ws, args);
}

void Assembler::addStagesTogether(const Model& model, Workspace& ws, const StageArgs& args) {
  const auto& components = model.components();
  for (std::size_t first = 0; first < together_.size(); first += kBatch) {
    const int count = static_cast<int>(std::min<std::size_t>(kBatch, together_.size() - first));
    forEachSlot(count, [&](int b) {
      const Component& component = *components[together_[first + b]];
      LocalSystem out[CollocationRule::kMostStages];
      for (int l = 0; l < stages_; ++l) {
        out[l] = {static_cast<int>(component.dofs().size()), locals_[b].r + l * largest_, locals_[b].k};
        std::fill_n(out[l].r, out[l].n, 0.0);
        localFlows_[b * stages_ + l] = Flows{};
      }
      component.stageResiduals(args, ws, out, &localFlows_[b * stages_]);
    });
    for (int b = 0; b < count; ++b) {
      const std::size_t c = together_[first + b];
      for (int l = 0; l < stages_; ++l) {
        scatterResidual(c, components[c]->dofs(), locals_[b].r + l * largest_, l, 1.0);
        const Flows flows = localFlows_[b * stages_ + l] * args.rule->weight[l];
        flows_ += flows;
        if (keepComponentFlows_) componentFlows_[c] += flows;
      }
    }
  }
}

void Assembler::imposeStageMotions(const Model& model, const StageArgs& args) {
  const auto& prescribed = model.prescribedMotions();
  for (int l = 0; l < stages_; ++l) {
    const double* z = args.stageState[l];
    const double t = args.t + args.rule->node[l] * args.dt;
    for (std::size_t k = 0; k < prescribed.size(); ++k) {
      const PrescribedMotion& p = prescribed[k];
      // a velocity or temperature follows the profile's change since the step's start, as in
      // the one-stage steps: at the first stages, and over the whole step at the last one (the
      // end value's change, so that the step ends on the profile); a displacement gives the
      // velocity as its slope
      const bool endRow = p.kind != PrescribedKind::Displacement && stages_ > 1 && l == stages_ - 1 && hasEndEntries(k);
      double value = z[p.dof] - args.zOld[p.dof] - p.amplitude * (p.profile(t) - p.profile(args.t));
      if (p.kind == PrescribedKind::Displacement) value = z[p.dof] - p.amplitude * p.profile.slope(t);
      if (endRow)
        value = args.zEnd[p.dof] - args.zOld[p.dof] - p.amplitude * (p.profile(args.t + args.dt) - p.profile(args.t));
      // heat through a prescribed temperature enters at the stage temperature its cells use
      StageArgs atStage = args;
      atStage.stage = atStage.column = l;
      const double conjugate =
          p.kind == PrescribedKind::Temperature ? stageTemperature(atStage, p.dof).value : z[p.dof];
      replaceRow(k, p, value, endRow ? args.rule->end[l + 1] : 1.0, conjugate, l, args.rule->weight[l]);
      if (endRow)
        for (int m = 0; m < stages_; ++m)
          tangent_.valuePtr()[prescribedEndEntries_[k * stages_ + m]] = args.rule->end[m + 1];
    }
  }
}

void Assembler::imposeStepMotions(const Model& model, const double* zOld, const double* zNew, double t, double dt) {
  const auto& prescribed = model.prescribedMotions();
  for (std::size_t k = 0; k < prescribed.size(); ++k) {
    const PrescribedMotion& p = prescribed[k];
    const double change = p.amplitude * (p.profile(t + dt) - p.profile(t));
    const double meanVelocity = 0.5 * (zOld[p.dof] + zNew[p.dof]);
    // heat through a prescribed temperature enters at the discrete temperature its cells use
    const double conjugate =
        p.kind == PrescribedKind::Temperature ? logarithmicMean(zOld[p.dof], zNew[p.dof]).value : meanVelocity;
    if (p.kind == PrescribedKind::Displacement)
      replaceRow(k, p, meanVelocity - change / dt, 0.5, conjugate);
    else
      replaceRow(k, p, (zNew[p.dof] - zOld[p.dof] - change) / dt, 1.0 / dt, conjugate);
  }
}

void Assembler::imposeRateMotions(const Model& model, const double* z, const double* zdot, double t, double beta) {
  const auto& prescribed = model.prescribedMotions();
  for (std::size_t k = 0; k < prescribed.size(); ++k) {
    const PrescribedMotion& p = prescribed[k];
    replaceRow(k, p, zdot[p.dof] - p.amplitude * p.profile.slope(t), beta, z[p.dof]);
  }
}

void Assembler::updateRowScale(const Eigen::VectorXd& stateScale) {
  rowScale_.setZero();
  for (int col = 0; col < tangent_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(tangent_, col); it; ++it)
      rowScale_[it.row()] += std::abs(it.value()) * stateScale[col];
}

int Assembler::describeNonFinite(const Model& model, char* out, std::size_t size) const {
  if (firstNonFinite_.component < 0 || size == 0) return 0;
  const std::string_view block = blockName(model.layout().blockOf(firstNonFinite_.dof));
  const int written =
      std::snprintf(out, size, "the residual of %s at dof %d (%.*s) was not finite at an iterate or trial of this step",
                    model.components()[firstNonFinite_.component]->name().c_str(), firstNonFinite_.dof,
                    static_cast<int>(block.size()), block.data());
  return written < 0 ? 0 : std::min(written, static_cast<int>(size) - 1);
}

double Assembler::relativeResidualNorm() const {
  double norm = 0.0;
  for (Eigen::Index i = 0; i < residual_.size(); ++i) {
    if (!std::isfinite(residual_[i])) return INFINITY;
    if (residual_[i] != 0.0) norm = std::max(norm, std::abs(residual_[i]) / rowScale_[i]);
  }
  return norm;
}

}  // namespace mpx
