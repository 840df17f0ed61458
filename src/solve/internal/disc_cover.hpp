#pragma once
// Covering a rectangle of the complex plane by a union of discs (the shift_invert covering,
// shift_invert.cpp): which part of a cell is left once every disc known so far is taken into
// account. A cell that lies inside no single disc may still lie inside their union (a failed
// resolvent test's disc next to an Arnoldi disc, two neighbouring tests): such a cell needs no
// LU of its own, and one that is partly covered is shrunk to the part left.

#include <algorithm>
#include <complex>
#include <limits>
#include <optional>
#include <vector>

namespace ddemap::detail {

/// A closed rectangle [x0, x1] x [y0, y1] of the complex plane.
struct Rect {
    double x0, x1, y0, y1;
};

/// An open disc |z - centre| < radius. Root-free (no root of the DDE inside: a resolvent test)
/// right of valid_from, or an Arnoldi disc (every collocation eigenvalue inside found).
struct Disc {
    std::complex<double> centre;
    double radius = 0.0;
    bool root_free = false;
    double valid_from = -std::numeric_limits<double>::infinity();  ///< root_free: the claim holds right of this line
};

/// The rectangle lies inside the disc (a disc is convex: its four corners do).
inline bool rect_in_disc(const Rect& r, const Disc& d) {
    const double r2 = d.radius * d.radius;
    for (double x : {r.x0, r.x1})
        for (double y : {r.y0, r.y1})
            if (!(std::norm(std::complex<double>(x, y) - d.centre) < r2)) return false;  // (a NaN radius covers nothing)
    return true;
}

/// The disc may cover part of the rectangle: it reaches it, and (root-free) the rectangle
/// reaches right of its valid_from.
inline bool disc_meets(const Rect& r, const Disc& d) {
    if (d.root_free && r.x1 < d.valid_from) return false;
    const double dx = std::max({r.x0 - d.centre.real(), 0.0, d.centre.real() - r.x1});
    const double dy = std::max({r.y0 - d.centre.imag(), 0.0, d.centre.imag() - r.y1});
    return dx * dx + dy * dy < d.radius * d.radius;
}

namespace cover_detail {
inline bool cover_piece(const Rect& p, const std::vector<Disc>& discs, const std::vector<std::size_t>& near, int depth,
                        Rect& box, std::vector<Rect>& arnoldi) {
    for (const bool root_free : {true, false})
        for (const std::size_t i : near) {
            const Disc& d = discs[i];
            if (d.root_free != root_free || p.x0 < d.valid_from || !rect_in_disc(p, d)) continue;
            if (!root_free) arnoldi.push_back(p);
            return true;
        }
    std::vector<std::size_t> still;
    for (const std::size_t i : near)
        if (disc_meets(p, discs[i])) still.push_back(i);
    if (depth == 0 || still.empty()) {
        box.x0 = std::min(box.x0, p.x0);
        box.x1 = std::max(box.x1, p.x1);
        box.y0 = std::min(box.y0, p.y0);
        box.y1 = std::max(box.y1, p.y1);
        return false;
    }
    Rect a = p, b = p;
    if (p.x1 - p.x0 >= p.y1 - p.y0) {
        a.x1 = b.x0 = 0.5 * (p.x0 + p.x1);
    } else {
        a.y1 = b.y0 = 0.5 * (p.y0 + p.y1);
    }
    const bool first = cover_piece(a, discs, still, depth - 1, box, arnoldi);
    const bool second = cover_piece(b, discs, still, depth - 1, box, arnoldi);
    return first && second;
}
}  // namespace cover_detail

/// The part of `r` the discs leave: nullopt when their union covers it, else the bounding box of
/// the pieces left. `r` is halved across its longer side up to `depth` times (2^depth pieces at
/// most); a piece is covered when it lies inside one disc, a root-free one only where the piece
/// lies right of its valid_from, root-free discs tried first. A sufficient test: a covered
/// answer is always right, a piece that the union covers only in parts finer than the last
/// halving counts as left. `on_arnoldi(piece)` is called for each piece that is covered by an
/// Arnoldi disc and not inside the box returned (the covering raises the extent the collocation
/// must resolve; the box is looked at again, or shown root-free, by the caller).
template <class OnArnoldi>
std::optional<Rect> uncovered_part(const Rect& r, const std::vector<Disc>& discs, int depth, OnArnoldi on_arnoldi) {
    std::vector<std::size_t> near;
    for (std::size_t i = discs.size(); i-- > 0;)  // the newest first: they are the smaller, nearer ones
        if (disc_meets(r, discs[i])) near.push_back(i);
    constexpr double inf = std::numeric_limits<double>::infinity();
    Rect box{inf, -inf, inf, -inf};
    std::vector<Rect> arnoldi;
    const bool covered = cover_detail::cover_piece(r, discs, near, depth, box, arnoldi);
    for (const Rect& p : arnoldi)
        if (covered || p.x0 < box.x0 || p.x1 > box.x1 || p.y0 < box.y0 || p.y1 > box.y1) on_arnoldi(p);
    if (covered) return std::nullopt;
    return box;
}

}  // namespace ddemap::detail
