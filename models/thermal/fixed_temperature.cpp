#include "models/thermal/fixed_temperature.hpp"

namespace mpx {

FixedTemperature::FixedTemperature(std::string name, int node, double temperature)
    : Component(std::move(name), {}), node_(node), temperature_(temperature) {}

void FixedTemperature::measure(const double*, Measures& out) const { out.nodeTemperature[node_] = temperature_; }

void FixedTemperature::publish(Workspace& ws) const {
  ws.nodes[node_].value = temperature_;
  ws.nodes[node_].count = 0;
}

void FixedTemperature::eemLocal(const StepArgs&, Workspace& ws, LocalSystem&, Flows&) const { publish(ws); }

void FixedTemperature::rateLocal(const RateArgs&, Workspace& ws, LocalSystem&, Flows&) const { publish(ws); }

}  // namespace mpx
