#pragma once
// capsflow::fmm equivalent kernels — which kernel the KIFMM's equivalent densities use.
//
// A kernel K may name the kernels of its equivalent densities:
//   K::UpwardEquivalent   — upward (multipole) densities: M2M, M2L, M2P and the upward pseudo-inverse;
//   K::DownwardEquivalent — downward (local) densities: L2L, L2P and the downward pseudo-inverse.
// Without them both are K itself (Stokeslet, Laplace). K is evaluated only from the real sources:
// P2M, P2L and the direct near field. Both equivalent kernels must map to K's target components
// and share one homogeneity degree h_E (the check potentials of a level of half-width ρ are kept
// multiplied by ρ^{−h_E}).
// An equivalent kernel may have density components of another degree: E::degree_shift(b) = degree
// of column b minus E::homogeneity (default 0). Such a component of a box of half-width ρ is
// stored multiplied by ρ^{degree_shift(b)} ("reference-scaled"), which keeps every operator
// level-independent (derivation: docs/fmm.md §3.10).
// K::net_force_free = true (default false) says that K's sums exert no net force (the stresslet);
// the upward densities, whose components 0–2 are then Stokeslet forces, are kept free of net force
// too (operators.hpp): a spurious net force decays like 1/r against the sources' 1/r², so it would
// grow relative to them by 2 per level of M2M.
#include <type_traits>

namespace capsflow::fmm {

template <class K, class = void>
struct UpwardEquivalentOf { using type = K; };
template <class K>
struct UpwardEquivalentOf<K, std::void_t<typename K::UpwardEquivalent>> { using type = typename K::UpwardEquivalent; };

template <class K, class = void>
struct DownwardEquivalentOf { using type = K; };
template <class K>
struct DownwardEquivalentOf<K, std::void_t<typename K::DownwardEquivalent>> { using type = typename K::DownwardEquivalent; };

/// true if K names an equivalent kernel other than itself (its operators then carry the names of both)
template <class K>
inline constexpr bool has_own_equivalents = !std::is_same_v<typename UpwardEquivalentOf<K>::type, K> ||
                                           !std::is_same_v<typename DownwardEquivalentOf<K>::type, K>;

template <class K, class = void>
struct NetForceFree : std::false_type {};
template <class K>
struct NetForceFree<K, std::void_t<decltype(K::net_force_free)>> : std::bool_constant<K::net_force_free> {};

template <class E, class = void>
struct HasDegreeShift : std::false_type {};
template <class E>
struct HasDegreeShift<E, std::void_t<decltype(E::degree_shift(0))>> : std::true_type {};

/// degree of density component b of E minus E::homogeneity
template <class E>
constexpr int degree_shift(int b) {
  if constexpr (HasDegreeShift<E>::value) return E::degree_shift(b);
  else return 0;
}

/// true if some density component of E has its own degree (needs per-component scaling)
template <class E>
constexpr bool has_degree_shift() {
  for (int b = 0; b < E::src_dim; ++b)
    if (degree_shift<E>(b) != 0) return true;
  return false;
}

}  // namespace capsflow::fmm
