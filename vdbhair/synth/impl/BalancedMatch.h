/// @file BalancedMatch.h
/// @brief The balanced matching of strands to members of detail transfer (DetailTransfer.cc,
/// step 4): the greedy over every (distance², strand, member) pair by increasing distance, ties
/// by strand then member, in which a strand takes the first member with room, taken lazily
/// through heaps instead of by sorting every pair. Included by DetailTransfer.cc and its test.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <tuple>
#include <utility>
#include <vector>

namespace vdbhair {
namespace detail {

/// A strand's candidate: (distance², member).
using MatchCandidate = std::pair<double, std::uint32_t>;

/// The greedy: @a cand holds strands × members candidates, row a = strand a's (distance², k) for
/// every member k in member order (reordered here); @a nearest[a] is the first member of least
/// distance in row a. A member serves at most @a cap strands. Calls take(a, k) for each pair
/// taken, in the order the sorted scan takes them; a strand left with no member takes none.
///
/// The same pairs as sorting every pair and scanning: each strand's row becomes a min-heap the
/// first time its nearest member is refused (with a cap above the even share most strands take
/// their nearest, and their rows are never heaped), and one global heap holds each unserved
/// strand's least pair not yet refused. A member refused once stays full (its use only grows),
/// so the global heap's top is always the next pair of the sorted scan that concerns an unserved
/// strand, and a pair the scan would skip for a served strand is never in it.
template<typename Take>
void balancedMatch(std::vector<MatchCandidate>& cand, std::size_t strands, std::size_t members,
                   const std::vector<std::uint32_t>& nearest, double cap, Take&& take)
{
    using Pair = std::tuple<double, std::uint32_t, std::uint32_t>;  // (distance², strand, member)
    std::vector<Pair> next;
    next.reserve(strands);
    for (std::size_t a = 0; a < strands; ++a)
        next.emplace_back(cand[a * members + nearest[a]].first, std::uint32_t(a), nearest[a]);
    std::make_heap(next.begin(), next.end(), std::greater<Pair>());
    std::vector<std::size_t> left(strands, 0);  // each strand's heap size, once made
    std::vector<double> used(members, 0.0);
    while (!next.empty()) {
        std::pop_heap(next.begin(), next.end(), std::greater<Pair>());
        const auto [d, a, k] = next.back();
        next.pop_back();
        (void)d;
        if (used[k] + 1.0 <= cap) {
            used[k] += 1.0;
            take(a, k);
            continue;
        }
        // Refused: the strand's next nearest member, if any.
        MatchCandidate* row = cand.data() + std::size_t(a) * members;
        if (left[a] == 0) {
            // First refusal: the other members as a heap (the refused one, the least, set aside;
            // rows are in member order until then, so row[k] is member k).
            std::swap(row[k], row[members - 1]);
            left[a] = members - 1;
            std::make_heap(row, row + left[a], std::greater<MatchCandidate>());
        } else {
            std::pop_heap(row, row + left[a], std::greater<MatchCandidate>());
            --left[a];
        }
        if (left[a] == 0) continue;  // no member left
        next.emplace_back(row[0].first, a, row[0].second);
        std::push_heap(next.begin(), next.end(), std::greater<Pair>());
    }
}

} // namespace detail
} // namespace vdbhair
