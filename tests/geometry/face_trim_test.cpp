// face_trim.hpp: a face's trimming loops as rational arcs, and where points and boxes of the
// parameter plane lie. The reference written here: each loop sampled densely into a polygon
// (4,000 points per arc) and the even-odd crossing rule on it, for points farther from the
// polygon than its chordal error; on thousands of random points against random polygons with
// weighted vertices, exact circles (rational quadratic arcs), random cubic loops (which may
// cross themselves), holes running either way, arcs reversed, and gaps between arc ends.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "scallop/geometry/face_trim.hpp"

namespace {

using scallop::CellPlace;
using scallop::FaceTrim;
using scallop::ParameterBox;
using scallop::TrimArc;

struct Point {
  double u, v;
};

// The arc's point at t (de Casteljau on the homogeneous poles).
Point evaluate(const TrimArc& arc, double t) {
  TrimArc p = arc;
  for (std::size_t level = 1; level < p.size(); ++level)
    for (std::size_t i = 0; i + level < p.size(); ++i)
      for (std::size_t c = 0; c < 3; ++c) p[i][c] = (1.0 - t) * p[i][c] + t * p[i + 1][c];
  return {p[0][0] / p[0][2], p[0][1] / p[0][2]};
}

TrimArc arcOf(const std::vector<Point>& poles, const std::vector<double>& weights) {
  TrimArc arc;
  for (std::size_t i = 0; i < poles.size(); ++i)
    arc.push_back({weights[i] * poles[i].u, weights[i] * poles[i].v, weights[i]});
  return arc;
}

// A circle as four rational quadratic arcs (exact), counter-clockwise or not.
std::vector<TrimArc> circle(Point centre, double radius, bool clockwise) {
  std::vector<TrimArc> arcs;
  const double w = std::sqrt(0.5);
  for (int q = 0; q < 4; ++q) {
    const double a = q * std::numbers::pi / 2.0, b = a + std::numbers::pi / 2.0;
    const Point start{centre.u + radius * std::cos(a), centre.v + radius * std::sin(a)};
    const Point end{centre.u + radius * std::cos(b), centre.v + radius * std::sin(b)};
    const Point corner{centre.u + radius * (std::cos(a) + std::cos(b)), centre.v + radius * (std::sin(a) + std::sin(b))};
    arcs.push_back(arcOf({start, corner, end}, {1.0, w, 1.0}));
  }
  if (clockwise) {  // each arc backwards, and the arcs in the reverse order: still one loop
    std::reverse(arcs.begin(), arcs.end());
    for (TrimArc& arc : arcs) std::reverse(arc.begin(), arc.end());
  }
  return arcs;
}

// The loops sampled into polygons (each arc 4,000 chords), for the reference.
struct Reference {
  std::vector<std::vector<Point>> polygons;  // one per arc; joined in any order the parity holds
  double chordError = 0.0;

  explicit Reference(const FaceTrim& trim) {
    for (const TrimArc& arc : trim.arcs) {
      std::vector<Point> polygon;
      for (int i = 0; i <= 4000; ++i) polygon.push_back(evaluate(arc, i / 4000.0));
      polygons.push_back(polygon);
    }
  }

  // The even-odd rule on the sampled loops (ray towards +u), and the distance to them. The
  // sampled arcs meet end to end as the arcs do; a gap between two ends is closed by a chord.
  bool inside(Point p) const {
    bool odd = false;
    const auto cross = [&](Point a, Point b) {
      if ((a.v > p.v) != (b.v > p.v)) {
        const double u = a.u + (p.v - a.v) / (b.v - a.v) * (b.u - a.u);
        if (u > p.u) odd = !odd;
      }
    };
    for (const auto& polygon : polygons)
      for (std::size_t i = 0; i + 1 < polygon.size(); ++i) cross(polygon[i], polygon[i + 1]);
    for (std::size_t k = 0; k < polygons.size(); ++k)  // gaps: each arc's end to its successor's start
      cross(polygons[k].back(), polygons[(k + 1) % polygons.size()].front());
    return odd;
  }

  double distance(Point p) const {
    double least = 1e300;
    for (const auto& polygon : polygons)
      for (std::size_t i = 0; i + 1 < polygon.size(); ++i) {
        const Point a = polygon[i], b = polygon[i + 1];
        const double du = b.u - a.u, dv = b.v - a.v, length2 = du * du + dv * dv;
        double t = length2 > 0.0 ? ((p.u - a.u) * du + (p.v - a.v) * dv) / length2 : 0.0;
        t = std::clamp(t, 0.0, 1.0);
        least = std::min(least, std::hypot(a.u + t * du - p.u, a.v + t * dv - p.v));
      }
    return least;
  }
};

// One random trim of the kinds in the header comment. Its loops are listed arc after arc, each
// loop's arcs in order, so that the reference's chords from each arc's end to the next arc's
// start close the gaps within a loop; between two closed loops the chord runs from one to
// the other and back, which changes no parity.
FaceTrim randomTrim(std::mt19937_64& rng, int kind) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), weight(0.3, 3.0);
  FaceTrim trim;
  const auto add = [&](std::vector<TrimArc> loop) {
    for (TrimArc& arc : loop) trim.arcs.push_back(std::move(arc));
  };
  switch (kind % 5) {
    case 0: {  // a star-shaped polygon with weighted vertices (the sides stay straight)
      const int sides = 3 + static_cast<int>(unit(rng) * 30);
      std::vector<Point> vertices;
      for (int i = 0; i < sides; ++i) {
        const double angle = 2.0 * std::numbers::pi * (i + 0.8 * unit(rng)) / sides, r = 0.3 + unit(rng);
        vertices.push_back({r * std::cos(angle), r * std::sin(angle)});
      }
      std::vector<TrimArc> loop;
      for (int i = 0; i < sides; ++i)
        loop.push_back(arcOf({vertices[i], vertices[(i + 1) % sides]}, {weight(rng), weight(rng)}));
      add(loop);
      break;
    }
    case 1:  // a circle
      add(circle({unit(rng), unit(rng)}, 0.2 + unit(rng), unit(rng) < 0.5));
      break;
    case 2: {  // a closed loop of random cubic arcs about the origin, perhaps crossing itself
      const int count = 2 + static_cast<int>(unit(rng) * 6);
      std::vector<Point> ends;
      for (int i = 0; i < count; ++i) {
        const double angle = 2.0 * std::numbers::pi * i / count;
        ends.push_back({std::cos(angle), std::sin(angle)});
      }
      std::vector<TrimArc> loop;
      for (int i = 0; i < count; ++i) {
        const Point a = ends[i], b = ends[(i + 1) % count];
        const Point c1{a.u + 1.2 * (unit(rng) - 0.5), a.v + 1.2 * (unit(rng) - 0.5)};
        const Point c2{b.u + 1.2 * (unit(rng) - 0.5), b.v + 1.2 * (unit(rng) - 0.5)};
        loop.push_back(arcOf({a, c1, c2, b}, {1.0, weight(rng), weight(rng), 1.0}));
      }
      add(loop);
      break;
    }
    case 3: {  // a square with a circular hole, either way round
      const Point s[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      std::vector<TrimArc> loop;
      for (int i = 0; i < 4; ++i) loop.push_back(arcOf({s[i], s[(i + 1) % 4]}, {1.0, 1.0}));
      add(loop);
      add(circle({0.3 * (unit(rng) - 0.5), 0.3 * (unit(rng) - 0.5)}, 0.2 + 0.5 * unit(rng), unit(rng) < 0.5));
      break;
    }
    default: {  // a circle whose arcs' ends stand 1e-10 apart (a model's tolerance)
      std::vector<TrimArc> loop = circle({0.0, 0.0}, 0.5 + unit(rng), false);
      for (TrimArc& arc : loop) arc.back()[0] += 1e-10 * arc.back()[2];
      add(loop);
      break;
    }
  }
  return trim;
}

TEST(FaceTrim, PointsAgreeWithTheEvenOddRuleOnDenseSamples) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int decided = 0, near = 0;
  for (int t = 0; t < 60; ++t) {
    const FaceTrim trim = randomTrim(rng, t);
    const Reference reference(trim);
    for (int i = 0; i < 200; ++i) {
      const Point p{-2.2 + 4.4 * unit(rng), -2.2 + 4.4 * unit(rng)};
      const CellPlace place = scallop::classifyPoint(trim, p.u, p.v);
      // The samples stand within about 1e-7 of the arcs; closer points are left out.
      if (reference.distance(p) < 1e-6) {
        ++near;
        continue;
      }
      ASSERT_NE(place, CellPlace::boundary) << "trim " << t << " point " << i << " (" << p.u << ", " << p.v << ")";
      EXPECT_EQ(place == CellPlace::inside, reference.inside(p))
          << "trim " << t << " point " << i << " (" << p.u << ", " << p.v << ")";
      ++decided;
    }
  }
  EXPECT_GT(decided, 11900);
  EXPECT_LT(near, 100);
}

// Points very close to a curve (1e-9 .. 1e-4 along its normal, either side) are still told
// apart; the arcs' own ends are on the curve: boundary.
TEST(FaceTrim, PointsNearTheCurveAndOnIt) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int t = 0; t < 20; ++t) {
    const FaceTrim trim = randomTrim(rng, 1 + 3 * (t % 2));  // circles: their inside is known in closed form
    // The circle's centre and radius from three points of it.
    const Point a = evaluate(trim.arcs[0], 0.0), b = evaluate(trim.arcs[0], 1.0), c = evaluate(trim.arcs[0], 0.5);
    const double d = 2.0 * (a.u * (b.v - c.v) + b.u * (c.v - a.v) + c.u * (a.v - b.v));
    const double a2 = a.u * a.u + a.v * a.v, b2 = b.u * b.u + b.v * b.v, c2 = c.u * c.u + c.v * c.v;
    const Point centre{(a2 * (b.v - c.v) + b2 * (c.v - a.v) + c2 * (a.v - b.v)) / d,
                       (a2 * (c.u - b.u) + b2 * (a.u - c.u) + c2 * (b.u - a.u)) / d};
    const double radius = std::hypot(a.u - centre.u, a.v - centre.v);
    for (int i = 0; i < 100; ++i) {
      const double angle = 2.0 * std::numbers::pi * unit(rng);
      const double offset = std::pow(10.0, -9.0 + 5.0 * unit(rng)) * (unit(rng) < 0.5 ? -1.0 : 1.0);
      const Point p{centre.u + (radius + offset) * std::cos(angle), centre.v + (radius + offset) * std::sin(angle)};
      const CellPlace place = scallop::classifyPoint(trim, p.u, p.v);
      if (t % 2 == 1 && std::abs(offset) < 1e-8) continue;  // the 1e-10 gaps: too close to call
      EXPECT_EQ(place, offset < 0.0 ? CellPlace::inside : CellPlace::outside) << t << " " << i << " offset " << offset;
    }
    for (const TrimArc& arc : trim.arcs) {
      const Point end = evaluate(arc, 0.0);
      EXPECT_EQ(scallop::classifyPoint(trim, end.u, end.v), CellPlace::boundary) << t;
    }
  }
}

// How one arc stands to one box by sampling, for mayMeet's reference: 1,024 chords over the
// arc, each chord that may come near the box 1,024 times finer, twice (a parameter step of
// 2^-30 near the box), until a sample lies in the box or the chords near it are below 1/64
// of its sides. A piece's points are taken to lie within twice its chord of its ends
// (the pieces are short beside the curve's bends); the Chebyshev distance (the larger of the
// u and v gaps) is the measure.
struct ArcNearBox {
  bool sampleInBox = false;          // a sample lies in the box, 1e-12 inside each side
  double lowerDistance = 1e300;      // a lower bound on the distance from the curve to `near`
};

double chebyshevGap(Point p, const ParameterBox& box) {
  return std::max({box.u0 - p.u, p.u - box.u1, box.v0 - p.v, p.v - box.v1, 0.0});
}

void sampleNear(const TrimArc& arc, const ParameterBox& box, const ParameterBox& near, double t0, double t1,
                int level, ArcNearBox& out) {
  constexpr int kChords = 1024;
  Point a = evaluate(arc, t0);
  for (int k = 1; k <= kChords; ++k) {
    const double ta = t0 + (t1 - t0) * (k - 1) / kChords, tb = t0 + (t1 - t0) * k / kChords;
    const Point b = evaluate(arc, tb);
    for (const Point& q : {a, b})
      out.sampleInBox = out.sampleInBox || (q.u >= box.u0 + 1e-12 && q.u <= box.u1 - 1e-12 &&
                                            q.v >= box.v0 + 1e-12 && q.v <= box.v1 - 1e-12);
    if (out.sampleInBox) return;  // decided: mayMeet must say "may meet"
    const double chord = std::max(std::abs(b.u - a.u), std::abs(b.v - a.v));
    const double lower = std::min(chebyshevGap(a, near), chebyshevGap(b, near)) - 2.0 * chord;
    // Finer only where it can still tell: a chord beside the box already below 1/64 of its
    // sides is fine enough (the curve there is within the eighth either way).
    const double side = std::min(box.u1 - box.u0, box.v1 - box.v0);
    if (lower <= 0.0 && level < 2 && (side == 0.0 || chord > side / 64.0)) {
      sampleNear(arc, box, near, ta, tb, level + 1, out);
    } else {
      out.lowerDistance = std::min(out.lowerDistance, lower);
    }
    a = b;
  }
}

// mayMeet (and halving alone, its peer in scallop-bench) against dense sampling, on 2,000
// random rational arcs of 1 to 9 poles (and some of 20 to 32) with weights from 0.1 to 10,
// among them degenerate ones (every pole the same, all on one line of constant v, repeated
// end poles), and boxes from 1e-5 to the arc's size placed near it: "may meet" whenever a
// sample lies in the box, and "misses" whenever the curve stays farther from the box than
// the contract's eighth of its size in u and v (the pieces that answer "may meet" are that
// small and meet the box): 8,000 boxes. A fifth box beside each arc is a point: no sample lies strictly inside it and
// there is no eighth to miss by, so those are run only to end (no hang, no throw).
TEST(FaceTrim, ArcsMeetBoxesAsDenseSamplesSay) {
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int meets = 0, misses = 0, between = 0, differ = 0;
  for (int a = 0; a < 2000; ++a) {
    const int kind = a % 10;
    std::size_t n = 1 + static_cast<std::size_t>(unit(rng) * 9);
    if (kind == 9) n = 20 + static_cast<std::size_t>(unit(rng) * 13);
    std::vector<Point> poles;
    std::vector<double> weights;
    for (std::size_t i = 0; i < n; ++i) {
      poles.push_back({2.0 * unit(rng) - 1.0, 2.0 * unit(rng) - 1.0});
      weights.push_back(std::pow(10.0, 2.0 * unit(rng) - 1.0));
    }
    if (kind == 6) std::fill(poles.begin(), poles.end(), poles.front());  // a point
    if (kind == 7)
      for (Point& p : poles) p.v = 0.25;  // a line of constant v
    if (kind == 8 && n >= 3) poles[1] = poles[0], poles[n - 2] = poles[n - 1];
    const TrimArc arc = arcOf(poles, weights);
    for (int b = 0; b < 5; ++b) {
      const Point on = evaluate(arc, unit(rng));
      const double size = b == 4 ? 0.0 : std::pow(10.0, -5.0 + 5.0 * unit(rng));
      const double aspect = std::pow(10.0, 2.0 * unit(rng) - 1.0);
      const double offset = std::pow(10.0, -6.0 + 6.0 * unit(rng)), angle = 2.0 * std::numbers::pi * unit(rng);
      const double su = size * aspect, sv = size / aspect;
      const double u0 = on.u + offset * std::cos(angle) - su * unit(rng);
      const double v0 = on.v + offset * std::sin(angle) - sv * unit(rng);
      const ParameterBox box{u0, u0 + su, v0, v0 + sv};
      const ParameterBox near{box.u0 - su / 8.0, box.u1 + su / 8.0, box.v0 - sv / 8.0, box.v1 + sv / 8.0};
      ArcNearBox reference;
      sampleNear(arc, box, near, 0.0, 1.0, 0, reference);
      const bool clipped = scallop::mayMeet(arc, box);
      const bool halved = scallop::detail::mayMeetByHalving(arc, box);
      for (int m = 0; m < 2; ++m) {
        const bool may = m == 0 ? clipped : halved;
        const char* method = m == 0 ? "mayMeet" : "by halving";
        if (reference.sampleInBox) {
          EXPECT_TRUE(may) << method << ": arc " << a << " box " << b;
        } else if (reference.lowerDistance > 0.0 && size > 0.0) {
          EXPECT_FALSE(may) << method << ": arc " << a << " box " << b << ": the curve stands "
                            << reference.lowerDistance << " or more from the box widened by an eighth";
        }
      }
      if (size == 0.0) continue;
      if (clipped != halved) ++differ;
      if (reference.sampleInBox) {
        ++meets;
      } else if (reference.lowerDistance > 0.0) {
        ++misses;
      } else {
        ++between;
      }
    }
  }
  // Both answers are asserted often (the counts leave out the point boxes, which assert nothing).
  EXPECT_GT(meets, 4000);
  EXPECT_GT(misses, 2500);
  std::printf("mayMeet: %d boxes met, %d missed, %d within an eighth of the box; clipping and halving differ on %d\n",
              meets, misses, between, differ);
}

// Boxes: inside or outside only when every point of the box is (dense samples and the
// reference), and boundary whenever a sample of the curve lies in the box.
TEST(FaceTrim, BoxesAreConservative) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int inside = 0, outside = 0, boundary = 0, corners = 0;
  for (int t = 0; t < 40; ++t) {
    const FaceTrim trim = randomTrim(rng, t);
    const Reference reference(trim);
    for (int i = 0; i < 100; ++i) {
      const double size = std::pow(10.0, -3.0 + 3.0 * unit(rng));
      const Point corner{-2.2 + 4.4 * unit(rng), -2.2 + 4.4 * unit(rng)};
      const ParameterBox box{corner.u, corner.u + size, corner.v, corner.v + size};
      const CellPlace place = scallop::classifyBox(trim, box);
      bool curveInBox = false;  // every 4th sample of the curve (1,000 per arc) looked at
      for (const auto& polygon : reference.polygons)
        for (std::size_t k = 0; k < polygon.size() && !curveInBox; k += 4)
          curveInBox = polygon[k].u >= box.u0 && polygon[k].u <= box.u1 && polygon[k].v >= box.v0 && polygon[k].v <= box.v1;
      if (curveInBox) {
        EXPECT_EQ(place, CellPlace::boundary) << t << " " << i;
      }
      if (place == CellPlace::boundary) {
        ++boundary;
        continue;
      }
      (place == CellPlace::inside ? inside : outside)++;
      // Random points of the box and its four corners (the gouge search takes a cell's place
      // from a corner: placeOfPoint's contract), against the reference.
      for (int k = 0; k < 10; ++k) {
        const Point p = k < 6 ? Point{box.u0 + size * unit(rng), box.v0 + size * unit(rng)}
                              : Point{(k & 1) != 0 ? box.u1 : box.u0, (k & 2) != 0 ? box.v1 : box.v0};
        if (reference.distance(p) < 1e-6) continue;
        EXPECT_EQ(reference.inside(p), place == CellPlace::inside) << t << " " << i << " " << k;
        if (k < 6) continue;
        // The corner's own winding gives the box's place, as the search asks it.
        EXPECT_EQ(scallop::classifyPoint(trim, p.u, p.v), place) << t << " " << i << " corner " << k;
        ++corners;
      }
    }
  }
  EXPECT_GT(inside, 200);
  EXPECT_GT(outside, 200);
  EXPECT_GT(boundary, 200);
  EXPECT_GT(corners, 4 * (inside + outside) - 100);  // corners within 1e-6 of the curve are few
  std::printf("[          ] boxes: %d inside, %d outside, %d boundary; %d corners checked\n", inside, outside,
              boundary, corners);
}

// The angle an arc sweeps: a circle's four quarters sweep pi / 2 each about its centre, and a
// full turn about any point inside; an arc sweeps nothing about a far point in line with it.
TEST(FaceTrim, SweptAnglesOfACircle) {
  const std::vector<TrimArc> arcs = circle({0.25, -0.5}, 2.0, false);
  for (const TrimArc& arc : arcs) EXPECT_NEAR(scallop::sweptAngle(arc, 0.25, -0.5), std::numbers::pi / 2.0, 1e-14);
  double total = 0.0;
  for (const TrimArc& arc : arcs) total += scallop::sweptAngle(arc, 1.5, 0.7);
  EXPECT_NEAR(total, 2.0 * std::numbers::pi, 1e-13);
  total = 0.0;
  for (const TrimArc& arc : arcs) total += scallop::sweptAngle(arc, 5.0, 0.0);
  EXPECT_NEAR(total, 0.0, 1e-13);
  const auto& start = arcs[1].front();  // the arc's start: on it
  EXPECT_TRUE(std::isnan(scallop::sweptAngle(arcs[1], start[0] / start[2], start[1] / start[2])));
}

}  // namespace
