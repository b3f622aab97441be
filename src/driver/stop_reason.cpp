#include "capsflow/core/driver/stop_reason.hpp"

#include <stdexcept>

namespace capsflow {

namespace {
const StopKindInfo& info(StopKind k) {
  for (const StopKindInfo& i : kStopKinds)
    if (i.kind == k) return i;
  throw std::logic_error("StopKind missing from kStopKinds");
}
}  // namespace

StopReason::StopReason(StopKind kind, std::string detail) : kind_(kind), detail_(std::move(detail)) {
  if (kind == StopKind::Health) throw std::logic_error("a health stop needs its condition: StopReason::health");
}

StopReason StopReason::health(HealthCondition condition, std::string detail) {
  StopReason r;
  r.kind_ = StopKind::Health;
  r.condition_ = condition;
  r.detail_ = std::move(detail);
  return r;
}

std::optional<StopReason> StopReason::parse(const std::string& text) {
  const std::size_t colon = text.find(':');
  const std::string name = text.substr(0, colon);
  // "name: detail": the detail starts after the colon and its space.
  std::string detail = colon == std::string::npos ? std::string() : text.substr(colon + 1);
  if (!detail.empty() && detail.front() == ' ') detail.erase(0, 1);
  for (const StopKindInfo& i : kStopKinds)
    if (i.name && name == i.name) return StopReason(i.kind, detail);
  if (const auto c = from_string<HealthCondition>(name)) return health(*c, detail);
  return std::nullopt;
}

std::string StopReason::name() const {
  return kind_ == StopKind::Health ? capsflow::to_string(*condition_) : info(kind_).name;
}

std::string StopReason::to_string() const { return detail_.empty() ? name() : name() + ": " + detail_; }

int StopReason::exit_code() const { return info(kind_).exit_code; }

}  // namespace capsflow
