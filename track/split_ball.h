#pragma once
// A ball cut into pieces by thin lines of another colour (a basketball's channels, a tennis
// ball's seam, a football's panel lines): its colour's mask is several components, none the
// ball. Closing the mask across gaps as wide as such lines joins the pieces; the joined region
// is taken for one blob only when it is one round blob (a disc, or a disc smeared along its
// motion) made mostly of the pieces, so that a patch of the ball's colour beside a ball is not
// merged into it (a disc and a patch together are neither round nor convex), nor are
// scattered specks taken for a ball (their closed region is mostly the gaps).
//
// Motion blur widens the lines (a falling basketball's channels blur to a fifth of its
// diameter), so the gaps bridged are wide: the closing runs on a grid of cells a few pixels
// across (any piece pixel sets its cell), whose cost does not grow with the gap.
#include <opencv2/core.hpp>

#include <vector>

namespace bouncefit {

// What a joined region must look like to be one ball.
struct SplitBallShape {
  // The joined region's area over that of the disc, or the disc drawn out along its motion,
  // that its box holds: near 1 for a round blob, less for a disc and a patch beside it.
  double min_roundness = 0.85;
  double max_roundness = 1.1;
  double min_solidity = 0.93;    // its area over its convex hull's: a ball is convex
  double min_piece_share = 0.55;  // the pieces' pixels over the joined region's: the lines are thin
  // A group whose largest piece holds more of its pieces' pixels is a ball whole with specks
  // or its reflection beside it (or a ball a line only nicks): not joined.
  double max_largest_piece = 0.9;
};

// One blob joined from several components.
struct JoinedPieces {
  std::vector<int> labels;  // the components it joins (labels of `labels`)
  cv::Rect box;             // of the pieces together, in the mask's coordinates
  cv::Point2d centroid;     // of the joined region, in the mask's coordinates
  int area = 0;             // of the joined region (the pieces and the lines between them), pixels
  bool touches_edge = false;  // it touches the mask's border
  cv::Mat region;           // CV_8U of box's size: 255 where the joined region is
};

// The components of a mask of mask_size, labelled within `box` (`labels`: CV_32S of box's
// size, 8-connected, 1..n-1, 0 background; `stats` per label in the mask's coordinates: as
// MaskComponents gives them), that lines up to gap_px wide (pixels) cut apart from each other
// and that together make one round blob of `shape` (its size is the caller's to check). A
// component is in at most one group; components alone are not listed. A group that touches
// the mask's border (a ball the search window cuts) is judged as it shows: a disc cut by a
// line is still convex, and round enough while the cut is shallower than half its radius.
std::vector<JoinedPieces> JoinSplitBall(const cv::Mat& labels, const cv::Mat& stats, cv::Rect box, cv::Size mask_size,
                                        int n, double gap_px, const SplitBallShape& shape);

}  // namespace bouncefit
