// The tracker's small parts on their own, a suite or two each (a test executable each would
// cost more to build than they take to run): track/mask_components, split_ball, circle_fit,
// motion_predictor, color_model, ycc_planes, shrink, change_map, ball_finder, ball_extent.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include "capture/frame.h"
#include "synth/synth_scene.h"
#include "track/ball_extent.h"
#include "track/ball_finder.h"
#include "track/change_map.h"
#include "track/circle_fit.h"
#include "track/color_model.h"
#include "track/mask_components.h"
#include "track/motion_predictor.h"
#include "track/shrink.h"
#include "track/split_ball.h"
#include "track/ycc_planes.h"

namespace bouncefit {
namespace {

// Labelling only the box around the set pixels gives what labelling the whole mask gives:
// the same components, areas, boxes and centroids, and each pixel's label; nothing set, none.
TEST(MaskComponents, TheSameComponentsAsLabellingTheWholeMask) {
  cv::Mat mask = cv::Mat::zeros(240, 320, CV_8U);
  cv::circle(mask, {200, 150}, 12, 255, cv::FILLED);
  cv::circle(mask, {120, 90}, 5, 255, cv::FILLED);
  cv::rectangle(mask, {150, 60}, {158, 100}, 255, cv::FILLED);
  cv::Mat whole, whole_stats, whole_centroids;
  const int n_whole = cv::connectedComponentsWithStats(mask, whole, whole_stats, whole_centroids, 8, CV_32S);
  cv::Mat labels, stats, centroids;
  cv::Rect box;
  const int n = MaskComponents(mask, &labels, &stats, &centroids, &box);
  ASSERT_EQ(n, n_whole);
  EXPECT_EQ(box, cv::Rect(115, 60, 98, 103));
  for (int k = 1; k < n; ++k) {
    for (int s : {cv::CC_STAT_LEFT, cv::CC_STAT_TOP, cv::CC_STAT_WIDTH, cv::CC_STAT_HEIGHT, cv::CC_STAT_AREA})
      EXPECT_EQ(stats.at<int>(k, s), whole_stats.at<int>(k, s)) << "label " << k;
    EXPECT_DOUBLE_EQ(centroids.at<double>(k, 0), whole_centroids.at<double>(k, 0));
    EXPECT_DOUBLE_EQ(centroids.at<double>(k, 1), whole_centroids.at<double>(k, 1));
  }
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      ASSERT_EQ(labels.at<int>(y - box.y, x - box.x), whole.at<int>(y, x)) << x << "," << y;
  EXPECT_EQ(MaskComponents(cv::Mat::zeros(240, 320, CV_8U), &labels, &stats, &centroids, &box), 1);
  EXPECT_EQ(box.area(), 0);
}

// The statistics gathered from the labels' runs are OpenCV's own, bit for bit, on masks of
// every kind: noise at any density, blurred blobs, empty and full masks, odd sizes.
TEST(ComponentsWithStats, WhatOpenCvsStatisticsGive) {
  cv::RNG rng(5);
  for (int it = 0; it < 200; ++it) {
    cv::Mat noise(rng.uniform(1, 160), rng.uniform(1, 160), CV_8U), blurred;
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    cv::blur(noise, blurred, {3, 3});
    const cv::Mat mask = it % 4 == 0 ? noise > rng.uniform(-1, 256) : blurred > rng.uniform(100, 156);
    cv::Mat l1, s1, c1, l2, s2, c2;
    const int n = cv::connectedComponentsWithStats(mask, l1, s1, c1, 8, CV_32S);
    ASSERT_EQ(ComponentsWithStats(mask, &l2, &s2, &c2), n);
    ASSERT_EQ(cv::countNonZero(l1 != l2), 0);
    for (int k = 1; k < n; ++k) {
      for (int s = 0; s < cv::CC_STAT_MAX; ++s) ASSERT_EQ(s1.at<int>(k, s), s2.at<int>(k, s)) << k;
      ASSERT_EQ(c1.at<double>(k, 0), c2.at<double>(k, 0)) << k;
      ASSERT_EQ(c1.at<double>(k, 1), c2.at<double>(k, 1)) << k;
    }
  }
}

// The groups JoinSplitBall makes of `mask`'s components, with the gap bridged (px).
std::vector<JoinedPieces> JoinedIn(const cv::Mat& mask, double gap_px, int* components = nullptr) {
  cv::Mat labels, stats, centroids;
  cv::Rect box;
  const int n = MaskComponents(mask, &labels, &stats, &centroids, &box);
  if (components) *components = n - 1;
  return JoinSplitBall(labels, stats, box, mask.size(), n, gap_px, SplitBallShape{});
}

// A basketball's disc, radius r at (x, y), cut by two lines across it and a ring, each
// `line` px wide: eight pieces and more.
void DrawSeamedDisc(cv::Mat& mask, double x, double y, double r, int line) {
  const cv::Point c(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
  cv::circle(mask, c, static_cast<int>(std::lround(r)), 255, cv::FILLED);
  cv::line(mask, c - cv::Point(static_cast<int>(r) + 2, 5), c + cv::Point(static_cast<int>(r) + 2, 5), 0, line);
  cv::line(mask, c - cv::Point(8, static_cast<int>(r) + 2), c + cv::Point(8, static_cast<int>(r) + 2), 0, line);
  cv::circle(mask, c + cv::Point(static_cast<int>(0.9 * r), 0), static_cast<int>(0.6 * r), 0, line);
}

// Pieces that thin lines cut a disc into are one blob: the disc's box, centre and area.
TEST(SplitBall, ThePiecesOfASeamedDiscAreOneBlob) {
  cv::Mat mask = cv::Mat::zeros(300, 300, CV_8U);
  DrawSeamedDisc(mask, 150.3, 140.6, 60, 6);
  int components = 0;
  const std::vector<JoinedPieces> g = JoinedIn(mask, 0.22 * 120, &components);
  ASSERT_GE(components, 6);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(static_cast<int>(g[0].labels.size()), components);
  EXPECT_NEAR(g[0].box.x, 90, 1);
  EXPECT_NEAR(g[0].box.width, 121, 1);
  EXPECT_NEAR(g[0].centroid.x, 150.3, 1.5);
  EXPECT_NEAR(g[0].centroid.y, 140.6, 1.5);
  EXPECT_NEAR(std::sqrt(g[0].area / std::numbers::pi), 60, 3);
  EXPECT_FALSE(g[0].touches_edge);
  // Smeared along its motion (a stadium) it is still one ball.
  cv::Mat smeared = cv::Mat::zeros(300, 300, CV_8U);
  for (int dy = 0; dy <= 40; dy += 2) DrawSeamedDisc(smeared, 150, 110 + dy, 50, 6);
  cv::line(smeared, {100, 145}, {200, 145}, 0, 6);
  EXPECT_EQ(JoinedIn(smeared, 0.22 * 100).size(), 1u);
}

// A patch of the ball's colour beside it is not merged into it: beside a whole disc, beside a
// seamed one (whose pieces then stay apart: the lines bridged would take in the patch too), and
// the disc with specks of its colour round it; nor is a cloud of specks a ball.
TEST(SplitBall, APatchBesideTheBallOrSpecksAreNotJoined) {
  cv::Mat whole = cv::Mat::zeros(300, 300, CV_8U);
  cv::circle(whole, {120, 150}, 50, 255, cv::FILLED);
  cv::rectangle(whole, {176, 110}, {230, 190}, 255, cv::FILLED);  // 6 px from the disc
  EXPECT_TRUE(JoinedIn(whole, 0.22 * 100).empty());

  cv::Mat seamed = cv::Mat::zeros(300, 300, CV_8U);
  DrawSeamedDisc(seamed, 120, 150, 50, 5);
  cv::circle(seamed, {196, 150}, 20, 255, cv::FILLED);  // a smaller ball of its colour, 6 px away
  for (const JoinedPieces& g : JoinedIn(seamed, 0.22 * 100)) EXPECT_LT(g.box.br().x, 172) << "the patch joined";

  cv::Mat specks = cv::Mat::zeros(300, 300, CV_8U);
  cv::circle(specks, {150, 150}, 50, 255, cv::FILLED);
  for (int k = 0; k < 8; ++k)
    cv::circle(specks, {150 + static_cast<int>(60 * std::cos(k)), 150 + static_cast<int>(60 * std::sin(k))}, 2, 255,
               cv::FILLED);
  EXPECT_TRUE(JoinedIn(specks, 0.22 * 100).empty());

  cv::Mat cloud = cv::Mat::zeros(300, 300, CV_8U);
  for (int y = 90; y <= 210; y += 12)
    for (int x = 90; x <= 210; x += 12)
      if (std::hypot(x - 150, y - 150) < 60) cv::circle(cloud, {x, y}, 2, 255, cv::FILLED);
  EXPECT_TRUE(JoinedIn(cloud, 0.22 * 100).empty());
}

TEST(CircleFit, IgnoresAFlattenedArcOfTheRim) {
  // 64 rim points of a circle (10.3, -4.2) r 7.5 with 0.1 px noise; a quarter of them pulled
  // 1.5 px inwards, as a shaded or occluded part of the rim would be.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.1);
  std::vector<EdgePoint> pts;
  for (int k = 0; k < 64; ++k) {
    const double a = 2 * std::numbers::pi * k / 64;
    const double r = 7.5 - (k >= 8 && k < 24 ? 1.5 : 0.0);
    pts.push_back({10.3 + r * std::cos(a) + noise(rng), -4.2 + r * std::sin(a) + noise(rng)});
  }
  const CircleFitResult fit = FitCircle(pts, {});
  ASSERT_TRUE(fit.ok);
  EXPECT_NEAR(fit.cx, 10.3, 0.05);
  EXPECT_NEAR(fit.cy, -4.2, 0.05);
  EXPECT_NEAR(fit.r, 7.5, 0.05);
  EXPECT_NEAR(fit.inlier_fraction, 0.75, 0.05);
}

TEST(CircleFit, TooFewPointsIsNotOk) {
  EXPECT_FALSE(FitCircle({{0, 0}, {1, 1}}, {}).ok);
}

TEST(MotionPredictor, FollowsAParabolaAndRestartsAtABounce) {
  MotionPredictor p;
  const double g = 3000;  // px/s^2
  auto y = [&](double t) { return 100 + 0.5 * g * t * t; };
  for (int i = 0; i < 10; ++i) p.Add(i / 120.0, 320 + i * 0.5, y(i / 120.0));
  double px, py, speed;
  ASSERT_TRUE(p.Predict(10 / 120.0, &px, &py, &speed));
  EXPECT_NEAR(px, 325, 1e-6);
  EXPECT_NEAR(py, y(10 / 120.0), 1e-6);
  EXPECT_NEAR(speed, std::hypot(60.0, g * 10 / 120.0), 1e-3);
  // A bounce: the ball comes back up; the far miss starts a new arc.
  p.Add(10 / 120.0, 325, y(9 / 120.0) - 5);
  EXPECT_EQ(p.arcs_started(), 1);
}

TEST(ColorModel, ShadingKeepsTheMatchWhiteAndGreyDoNot) {
  const ColorModel orange = ColorModel::FromBgr(20, 120, 250, {});
  double y, u, v;
  BgrToYuv(20 * 0.45, 120 * 0.45, 250 * 0.45, &y, &u, &v);  // the ball in shadow
  EXPECT_TRUE(orange.Matches(static_cast<float>(y), static_cast<float>(u), static_cast<float>(v)));
  BgrToYuv(196, 202, 206, &y, &u, &v);  // the wall
  EXPECT_FALSE(orange.Matches(static_cast<float>(y), static_cast<float>(u), static_cast<float>(v)));
  BgrToYuv(200, 120, 30, &y, &u, &v);  // a blue ball
  EXPECT_FALSE(orange.Matches(static_cast<float>(y), static_cast<float>(u), static_cast<float>(v)));
}

// The green ball clip: its colour read from a smear is a washed-out green (BGR 115,157,76); the
// body is the same hue twice as saturated (BGR 46,96,12): it matches, a blue-green does not,
// nor a dark pixel of that hue (a shadow), nor the surroundings' colour kept out; a colour
// read saturated already (orange) gets no reach.
TEST(ColorModel, AWashedOutColourMatchesTheBodysStrongerSameHue) {
  ColorModel washed = ColorModel::FromBgr(115, 157, 76, {});
  auto matches = [](const ColorModel& m, double b, double g, double r) {
    double y, u, v;
    BgrToYuv(b, g, r, &y, &u, &v);
    return m.Matches(static_cast<float>(y), static_cast<float>(u), static_cast<float>(v));
  };
  EXPECT_TRUE(matches(washed, 46, 96, 12));     // the body
  EXPECT_TRUE(matches(washed, 115, 157, 76));   // the washed-out colour itself
  EXPECT_FALSE(matches(washed, 140, 120, 20));  // blue-green
  EXPECT_FALSE(matches(washed, 12, 30, 2));     // the same hue, dark: shadow noise
  ColorModelParams disc;
  disc.saturation_reach = 1;
  EXPECT_FALSE(matches(ColorModel::FromBgr(115, 157, 76, disc), 46, 96, 12));
  double y, u, v;
  BgrToYuv(46, 96, 12, &y, &u, &v);
  washed.KeepOut(u / y, v / y);  // surroundings of the body's colour: no longer the ball's
  EXPECT_FALSE(matches(washed, 46, 96, 12));
  EXPECT_TRUE(matches(washed, 115, 157, 76));
  const ColorModel orange = ColorModel::FromBgr(20, 120, 250, {});
  EXPECT_FALSE(matches(orange, 0, 60, 250));    // a deeper red-orange is not taken in
}

// An orange ball dropped before a brown wall (chroma/luma of a real clip: the ball's body
// (-0.34, 0.35), the wall (-0.12, 0.17)), its colour first read from its smeared fall, between
// the two: (-0.20, 0.32). Its tolerance, 0.45 of that chroma, reached the wall itself (0.17
// away) and the ball's box grew to the window. Kept out, the wall stays beyond the tolerance
// with a margin, also once the colour adapts towards it; the ball's body still matches.
TEST(ColorModel, TheSurroundingsKeptOutStayBeyondTheTolerance) {
  ColorModel read(-0.20, 0.32, {});
  const double wall_u = -0.12, wall_v = 0.17, luma = 100;
  auto matches = [&](const ColorModel& m, double nu, double nv) {
    return m.Matches(static_cast<float>(luma), static_cast<float>(nu * luma), static_cast<float>(nv * luma));
  };
  const double wall_d = std::hypot(-0.20 - wall_u, 0.32 - wall_v);
  EXPECT_GE(read.tolerance(), 0.98 * wall_d);  // on the edge: about half the wall's pixels match
  read.KeepOut(wall_u, wall_v);
  EXPECT_LE(read.tolerance(), 0.75 * wall_d + 1e-9);
  EXPECT_FALSE(matches(read, wall_u, wall_v));
  EXPECT_FALSE(matches(read, wall_u - 0.02, wall_v + 0.03));  // the wall's noise towards the ball
  EXPECT_TRUE(matches(read, -0.34, 0.35));                    // the body, along the hue
  EXPECT_TRUE(matches(read, -0.20, 0.32));
  // Adapting towards a blend with the wall (a smeared frame's ball, within the tolerance, as
  // far as the tracker lets it drift: 0.3 of the colour) keeps the wall out.
  const ColorModel anchor = read;
  for (int k = 0; k < 40; ++k)
    read.AdaptTowards(-0.17, 0.26, 0.08, anchor, 0.3 * std::hypot(anchor.nu(), anchor.nv()));
  EXPECT_NEAR(read.nu(), -0.17, 0.01);
  EXPECT_FALSE(matches(read, wall_u, wall_v));
  EXPECT_LE(read.tolerance(), std::max(read.params().tolerance_min,
                                       0.75 * std::hypot(read.nu() - wall_u, read.nv() - wall_v)) + 1e-9);
}


// A row of pixels at once (eight a step where the processor has AVX2) gives each pixel's own
// Distance() bit for bit, and the match mask at the tolerance: dark pixels, pixels too dim for
// the saturation reach, the colour's own hue stronger, rows of every length (the vector tails).
TEST(ColorModel, DistanceRowGivesEachPixelsDistanceBitForBit) {
  ColorModel green = ColorModel::FromBgr(115, 157, 76, {});  // washed out: a reach along its hue
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> luma(0.0f, 255.0f), chroma(-128.0f, 127.0f);
  for (int n = 1; n <= 70; ++n) {
    std::vector<float> y(n), u(n), v(n), d(n);
    std::vector<uint8_t> match(n);
    for (int i = 0; i < n; ++i) {
      y[i] = luma(rng);
      // Half the pixels near the ball's colour at their own brightness (within and past the
      // tolerance, along the reach), the rest anything.
      const float s = i % 2 ? 0.5f + luma(rng) / 127.5f : 1.0f;
      u[i] = i % 2 ? y[i] * static_cast<float>(green.nu()) * s + chroma(rng) * 0.05f : chroma(rng);
      v[i] = i % 2 ? y[i] * static_cast<float>(green.nv()) * s + chroma(rng) * 0.05f : chroma(rng);
    }
    green.DistanceRow(y.data(), u.data(), v.data(), n, d.data(), match.data());
    for (int i = 0; i < n; ++i) {
      const float want = green.Distance(y[i], u[i], v[i]);
      ASSERT_EQ(std::memcmp(&d[i], &want, sizeof want), 0) << "n " << n << " pixel " << i << ": " << d[i] << " vs " << want;
      ASSERT_EQ(match[i], green.Matches(y[i], u[i], v[i]) ? 255 : 0) << "n " << n << " pixel " << i;
    }
  }
}

// The YCbCr planes of a BGR region, 16 pixels a step and the rest one by one, against the
// BT.601 formula in the same float operations, on random pixels, at offsets and widths around
// the steps; at full and half resolution (the means of 2x2 blocks).
TEST(ExtractYcc, BgrPixelsGiveTheFormulasFloatsExactly) {
  cv::RNG rng(11);
  cv::Mat image(40, 90, CV_8UC3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  Frame frame;
  frame.image = image;
  const float kr = 0.299f, kg = 0.587f, kb = 0.114f;
  const float cb = 0.5f / (1.0f - kb), cr = 0.5f / (1.0f - kr);
  // Rects at each step: offsets and widths around the 16-pixel steps (even ones at half
  // resolution, where a block starts on an even pixel).
  const std::vector<std::pair<int, std::vector<cv::Rect>>> cases = {
      {1, {{0, 0, 90, 40}, {3, 5, 15, 7}, {1, 2, 16, 3}, {7, 0, 33, 40}, {89, 39, 1, 1}}},
      {2, {{0, 0, 90, 40}, {4, 6, 34, 8}, {2, 2, 64, 6}, {8, 0, 66, 40}, {88, 38, 2, 2}}}};
  for (const auto& [step, rects] : cases)
    for (const cv::Rect& rect : rects) {
      YccPlanes p;
      ExtractYcc(frame, rect, step, 0, &p);
      ASSERT_EQ(p.y.size(), cv::Size(rect.width / step, rect.height / step));
      for (int j = 0; j < rect.height / step; ++j)
        for (int i = 0; i < rect.width / step; ++i) {
          int sum[3] = {0, 0, 0};  // of the step x step block, then x 1/step^2 as a float
          for (int dy = 0; dy < step; ++dy)
            for (int dx = 0; dx < step; ++dx)
              for (int c = 0; c < 3; ++c) sum[c] += image.at<cv::Vec3b>(rect.y + step * j + dy, rect.x + step * i + dx)[c];
          const float norm = 1.0f / static_cast<float>(step * step);
          const float b = sum[0] * norm, g = sum[1] * norm, r = sum[2] * norm;
          const float y = kr * r + kg * g + kb * b;
          ASSERT_EQ(p.y.at<float>(j, i), y) << "step " << step << ", " << rect << " at " << i << "," << j;
          ASSERT_EQ(p.u.at<float>(j, i), (b - y) * cb) << "step " << step << ", " << rect << " at " << i << "," << j;
          ASSERT_EQ(p.v.at<float>(j, i), (r - y) * cr) << "step " << step << ", " << rect << " at " << i << "," << j;
        }
    }
}

// The finder's shrink: cv::resize's INTER_AREA result, bit for bit, for the shared clips'
// frame and work sizes, 200 random sizes (factors 1 to 400) and 100 random whole factors
// (1 to 9 on each axis, 1 to 40 output pixels a row: the 16-byte steps and their tails).
TEST(ShrinkByArea, WhatCvResizeInterAreaGivesBitForBit) {
  std::vector<std::pair<cv::Size, cv::Size>> cases = {
      {{634, 1750}, {158, 437}}, {{634, 1750}, {79, 218}}, {{638, 360}, {159, 90}},
      {{864, 1034}, {216, 258}}, {{864, 1034}, {108, 129}}, {{1920, 1080}, {480, 270}},
      {{1920, 1080}, {240, 135}}, {{172, 1716}, {43, 429}}, {{450, 360}, {225, 180}},
      {{245, 10}, {5, 10}}, {{490, 490}, {10, 10}},  // 49: not whole as cv::resize derives it
      {{7, 5}, {2, 2}}, {{100, 3}, {33, 1}}, {{5, 5}, {5, 5}}, {{8, 8}, {4, 4}}};
  cv::RNG rng(5);
  for (int i = 0; i < 200; ++i) {
    const int w = rng.uniform(1, 400), h = rng.uniform(1, 300);
    cases.push_back({{w, h}, {rng.uniform(1, w + 1), rng.uniform(1, h + 1)}});
  }
  for (int i = 0; i < 100; ++i) {
    const int w = rng.uniform(1, 41), h = rng.uniform(1, 20), kx = rng.uniform(1, 10), ky = rng.uniform(1, 10);
    cases.push_back({{w * kx, h * ky}, {w, h}});
  }
  for (const auto& [from, to] : cases) {
    cv::Mat image(from, CV_8UC3), ours, theirs;
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    cv::resize(image, theirs, to, 0, 0, cv::INTER_AREA);
    ShrinkByArea(image, &ours, to);
    ASSERT_EQ(ours.size(), theirs.size()) << from << " -> " << to;
    ASSERT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0) << from << " -> " << to;
  }
}

// The finder's closing of its mask of moved pixels: cv::morphologyEx's MORPH_CLOSE with the
// 3x3 ellipse and its default border, pixel for pixel, on masks of widths around the 16-pixel
// steps, single rows and columns, and on any byte values (the max and min of them).
TEST(CloseByCross, WhatMorphologyExClosingWithThe3x3EllipseGives) {
  cv::RNG rng(3);
  const cv::Mat cross = cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3});
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 9), cv::Size(9, 1), cv::Size(2, 2), cv::Size(16, 5),
                              cv::Size(17, 4), cv::Size(18, 3), cv::Size(33, 7), cv::Size(86, 858), cv::Size(301, 37)})
    for (const bool binary : {true, false}) {
      cv::Mat mask(size, CV_8U), theirs;
      rng.fill(mask, cv::RNG::UNIFORM, 0, 256);
      if (binary) mask = mask > 170;
      cv::morphologyEx(mask, theirs, cv::MORPH_CLOSE, cross);
      CloseByCross(mask);
      ASSERT_EQ(cv::norm(mask, theirs, cv::NORM_INF), 0) << size << (binary ? " binary" : " bytes");
    }
}

// The finder's change map and its noise median, against OpenCV's absdiff and a sort, on
// random pictures of widths around the 16-pixel steps (and large differences, where the
// sum saturates).
TEST(ChangeMap, WhatAbsdiffAndASaturatedSumGive) {
  cv::RNG rng(7);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(15, 3), cv::Size(16, 4), cv::Size(17, 9), cv::Size(301, 37)}) {
    cv::Mat a(size, CV_8UC3), b(size, CV_8UC3);
    rng.fill(a, cv::RNG::UNIFORM, 0, 256);
    rng.fill(b, cv::RNG::UNIFORM, 0, 256);
    cv::Mat d, d3;
    ChangeMap(a, b, d);
    cv::absdiff(a, b, d3);
    std::vector<float> sample;
    for (int j = 0; j < size.height; ++j)
      for (int i = 0; i < size.width; ++i) {
        const cv::Vec3b v = d3.at<cv::Vec3b>(j, i);
        ASSERT_EQ(d.at<uint8_t>(j, i), std::min(255, v[0] + v[1] + v[2])) << size << " at " << i << "," << j;
        if (j % 4 == 0 && i % 4 == 0) sample.push_back(d.at<uint8_t>(j, i));
      }
    std::nth_element(sample.begin(), sample.begin() + static_cast<long>(sample.size() / 2), sample.end());
    EXPECT_EQ(MedianOfEvery4th(d), sample[sample.size() / 2]) << size;
  }
  EXPECT_EQ(MedianOfEvery4th(cv::Mat(0, 0, CV_8U)), 0);
}

// A 320x240 scene and two finders fed the same frames in different ways.
struct TwoFinders {
  static SynthSceneConfig Config() {
    SynthSceneConfig sc;
    sc.width = 320, sc.height = 240, sc.floor_y_px = 220;
    return sc;
  }
  SynthScene scene{Config()};
  BallFinder every{BallFinderParams{}, ColorModelParams{}}, some{BallFinderParams{}, ColorModelParams{}};
  cv::Rect roi{0, 0, 320, 240};
};

// A lock that holds only feeds frames to the finder's history (BallFinder::Remember); the
// finder called again later must compare the same frames and find the same ball as one that
// searched every frame (the history converted lazily, buffers reused).
TEST(BallFinder, FramesOnlyRememberedGiveTheSameCandidatesAsFramesSearched) {
  TwoFinders two;
  auto& [scene, every, some, roi] = two;
  int compared = 0, found = 0;
  for (int i = 0; i < 40; ++i) {
    const double t = i / 60.0;
    BallShape ball;
    ball.x = 100 + 60 * t, ball.y = 30 + 0.5 * 900 * t * t, ball.a = ball.b = 9;
    Frame f;
    scene.Render({ball}, &f.image);
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    const std::vector<BallCandidate> a = every.Find(f, roi);
    if (i % 7 < 4) {  // four frames of each seven only remembered
      some.Remember(f, roi);
      continue;
    }
    const std::vector<BallCandidate> b = some.Find(f, roi);
    ++compared;
    ASSERT_EQ(a.size(), b.size()) << "frame " << i;
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].x, b[k].x) << "frame " << i;
      EXPECT_EQ(a[k].y, b[k].y) << "frame " << i;
      EXPECT_EQ(a[k].r, b[k].r) << "frame " << i;
    }
    if (!a.empty() && std::hypot(a[0].x - ball.x, a[0].y - ball.y) < 4) ++found;
  }
  EXPECT_EQ(compared, 16);
  EXPECT_GE(found, 12) << "the ball itself is found where the finder searched";
}

// A frame whose memory is its own (Frame::owns_image, as a file or a camera delivers) is kept
// without a copy; one whose source reuses its buffer is copied. Mixed, the finder compares
// the frames it saw and never writes to a frame's own memory (its buffers are reused only
// where it copied).
TEST(BallFinder, KeepsFramesOwnImagesWithoutWritingToThemAndCopiesTheOthers) {
  TwoFinders two;
  auto& [scene, every, some, roi] = two;
  cv::Mat reused;  // a source's one buffer, written again for every frame it does not give away
  std::vector<std::pair<cv::Mat, cv::Mat>> owned;  // each owned image, and a copy of it
  int compared = 0;
  for (int i = 0; i < 60; ++i) {
    const double t = i / 60.0;
    BallShape ball;
    ball.x = 100 + 60 * t, ball.y = 30 + 0.5 * 900 * (t - 0.5) * (t - 0.5), ball.a = ball.b = 9;
    Frame f;
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    f.owns_image = i % 3 != 0;
    if (f.owns_image) {
      scene.Render({ball}, &f.image);
      owned.emplace_back(f.image, f.image.clone());
    } else {
      scene.Render({ball}, &reused);
      f.image = reused;
    }
    Frame fresh = f;
    fresh.image = f.image.clone();
    fresh.owns_image = false;
    const std::vector<BallCandidate> a = every.Find(fresh, roi);
    if (i % 5 < 3) {
      some.Remember(f, roi);
      continue;
    }
    const std::vector<BallCandidate> b = some.Find(f, roi);
    if (!a.empty()) ++compared;
    ASSERT_EQ(a.size(), b.size()) << "frame " << i;
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].x, b[k].x) << "frame " << i;
      EXPECT_EQ(a[k].y, b[k].y) << "frame " << i;
    }
  }
  EXPECT_GE(compared, 15) << "the finder must have found the ball to compare";
  for (const auto& [image, copy] : owned) EXPECT_EQ(cv::norm(image, copy, cv::NORM_INF), 0);
}

// Boxes measured on real clips. Two 20 fps ping-pong clips (ball radius 6 and 9 px): the
// ball merged with a strip of floor at its impact (165 x 17 px, falling at 36 px a frame),
// then the strip alone (37 x 6 px; 28 x 6 and 35 x 5 px) that the lock slid off with for
// 0.8-1.4 s; the shared football clip (radius 36 px): a 136 x 6 px patch of floor it sat on
// for three frames after the first impact. None is the ball. What is: a ball smeared by its
// fall (12 x 26 px), a tennis ball of radius 15 px at rest merged with its shadow (57 x 35
// px), a basketball of radius 39 px smeared at 24 fps.
TEST(BallExtent, StripsAreNotTheBallSmearsAndShadowsAre) {
  const double fall = MaxBallExtentPx(6, 36 * 20, 0.05), rest = MaxBallExtentPx(6, 0, 0.05);
  EXPECT_FALSE(BoxCanBeBall(165, 17, 6, fall));
  EXPECT_FALSE(BoxCanBeBall(37, 6, 6, rest));
  EXPECT_FALSE(BoxCanBeBall(37, 6, 6, 0)) << "thin and long whatever the speed";
  EXPECT_FALSE(BoxCanBeBall(28, 6, 9, MaxBallExtentPx(9, 55 * 20, 0.05)));
  EXPECT_FALSE(BoxCanBeBall(35, 5, 9, MaxBallExtentPx(9, 0, 0.05)));
  EXPECT_FALSE(BoxCanBeBall(136, 6, 36, MaxBallExtentPx(36, 0, 0.05)));
  EXPECT_TRUE(BoxCanBeBall(12, 26, 6, fall));
  EXPECT_TRUE(BoxCanBeBall(14, 14, 6, rest));
  EXPECT_TRUE(BoxCanBeBall(57, 35, 15, MaxBallExtentPx(15, 0, 0.05)));
  EXPECT_TRUE(BoxCanBeBall(78, 120, 39, MaxBallExtentPx(39, 900, 1 / 24.0)));
  EXPECT_TRUE(BoxCanBeBall(6, 12, 6, rest)) << "a ball cut in half by the frame's edge";
}

}  // namespace
}  // namespace bouncefit
