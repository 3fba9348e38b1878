// What World::chargeBudget charges per item the world script adds: estimates of the bytes each
// takes, measured with the peak RSS of worlds made of many of them (docs/limits.md): a cloth of
// 256 x 256 nodes adds about 85 MB (1.3 KB a node), 2 M debris particles about 520 MB (260 B).
#pragma once

namespace rm3d::budget {

constexpr double kBody = 4096;        ///< a body or a module's link, before its shape data
constexpr double kMeshPoint = 24;     ///< per mesh point
constexpr double kMeshIndex = 4;      ///< per triangle index
constexpr double kHeightSample = 16;  ///< per heightfield sample
constexpr double kClothNode = 1536;   ///< per cloth node (Bullet's node, links and faces)
constexpr double kParticle = 320;     ///< per fluid or debris particle
/// A module's spawn params, per value (keys included) and per string byte: the copy the module
/// keeps and the one in its behaviour's VM. Measured: 20 modules given 120,000 numbers each add
/// 686 MB (143 B a value), given a 4 MB string 192 MB (2.4 B a byte).
constexpr double kParamsValue = 144;
constexpr double kParamsByte = 2.5;

}  // namespace rm3d::budget
