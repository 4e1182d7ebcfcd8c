#pragma once
// Connected components of a binary mask, labelled only inside the box around its set pixels:
// OpenCV's labelling costs about 7 ns a pixel whatever it finds, and the masks of a whole-frame
// search are mostly empty (docs/PERFORMANCE.md). Same results as labelling the whole mask.
#include <opencv2/core.hpp>

namespace bouncefit {

// cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S), the same
// results for every component (the background, label 0, gets zeros), faster: OpenCV's
// statistics cost 5-7x its labelling (137 against 21 us on a 141 px square mask), where one
// pass over the labels' runs gathers them.
int ComponentsWithStats(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats, cv::Mat* centroids);

// 8-connected components of `mask` (CV_8U, non-zero = set). *box: the bounding box of the set
// pixels (empty: none); *labels: CV_32S of the box's size, the labels of its pixels (mask pixel
// (x, y) is labels(y - box.y, x - box.x)); *stats and *centroids as
// cv::connectedComponentsWithStats gives them, in the mask's coordinates. Returns the number of
// labels, background included (1 when nothing is set).
int MaskComponents(const cv::Mat& mask, cv::Mat* labels, cv::Mat* stats, cv::Mat* centroids,
                   cv::Rect* box);

}  // namespace bouncefit
