#pragma once
// The named choices of a scene that belong to no single module, as enums with ONE name table each
// (the TOML spelling, capsflow/core/named_enum.hpp). Parsing, validation messages, `capsflow
// info`, summary.json and checkpoints all read the tables. Choices owned by a module are named
// there: the membrane law in shell/laws.hpp, the mesh base solid in mesh/generation.hpp, the
// far-field back end and the surface geometry in bie/backend_choice.hpp.
#include "capsflow/core/named_enum.hpp"

namespace capsflow {

enum class MeshShape { Sphere, Spheroid, Biconcave };
enum class WallModel { Membrane, Gsmb };
enum class FlowType { PlanarHyperbolic, SimpleShear, Linear, Quiescent, Poiseuille };
enum class ChannelKind { None, Tube, SquareDuct, ConstrictedDuct };
enum class OutputField { Velocity, Load, Energy };

inline constexpr NameTable<MeshShape, 3> kMeshShapeNames{
    {{MeshShape::Sphere, "sphere"}, {MeshShape::Spheroid, "spheroid"}, {MeshShape::Biconcave, "biconcave"}}};
inline constexpr NameTable<WallModel, 2> kWallModelNames{{{WallModel::Membrane, "membrane"}, {WallModel::Gsmb, "gsmb"}}};
inline constexpr NameTable<FlowType, 5> kFlowTypeNames{{{FlowType::PlanarHyperbolic, "planar_hyperbolic"},
                                                        {FlowType::SimpleShear, "simple_shear"},
                                                        {FlowType::Linear, "linear"},
                                                        {FlowType::Quiescent, "quiescent"},
                                                        {FlowType::Poiseuille, "poiseuille"}}};
inline constexpr NameTable<ChannelKind, 4> kChannelKindNames{{{ChannelKind::None, "none"},
                                                              {ChannelKind::Tube, "tube"},
                                                              {ChannelKind::SquareDuct, "square_duct"},
                                                              {ChannelKind::ConstrictedDuct, "constricted_duct"}}};
inline constexpr NameTable<OutputField, 3> kOutputFieldNames{
    {{OutputField::Velocity, "velocity"}, {OutputField::Load, "load"}, {OutputField::Energy, "energy"}}};

// The table of each enum, found by overload on a value of the enum.
constexpr const auto& name_table(MeshShape) { return kMeshShapeNames; }
constexpr const auto& name_table(WallModel) { return kWallModelNames; }
constexpr const auto& name_table(FlowType) { return kFlowTypeNames; }
constexpr const auto& name_table(ChannelKind) { return kChannelKindNames; }
constexpr const auto& name_table(OutputField) { return kOutputFieldNames; }

}  // namespace capsflow
