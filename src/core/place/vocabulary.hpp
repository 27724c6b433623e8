#pragma once
// A hierarchical vocabulary of binary words over ORB descriptors (the bag of binary words of
// Galvez-Lopez and Tardos): a tree of branching k and depth L built by k-majority clustering
// (k-means++ seeding, Hamming distance, bitwise-majority centres), with an IDF weight per
// leaf word. An image's descriptors become a TF-IDF BowVector (for place recognition) and a
// FeatureVector (for matching features within the same node).
//
// Binary file format (little endian), version 1:
//   "HSVOCAB1" | u32 k | u32 L | u32 node count | nodes in breadth-first order, each:
//   u32 parent (root: 0xffffffff) | i32 word id (-1 for inner nodes) | f32 weight | 32 B descriptor
#include <array>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "core/place/bow_vector.hpp"

namespace hiveslam::place {

struct VocabularyOptions {
  int branching = 10;  // k
  int depth = 4;       // L: up to k^L words
  int iterations = 10; // k-majority rounds per node
  uint64_t seed = 1;
};

class Vocabulary {
 public:
  using Descriptor = std::array<uint8_t, 32>;

  // Builds the tree from the descriptors of many images (one cv::Mat of 32-byte rows each) and
  // weights each word by log(images / images containing it).
  static Vocabulary train(const std::vector<cv::Mat>& images, const VocabularyOptions& options = {});
  // Throws InputError (one line) on a missing, truncated or foreign file.
  static Vocabulary load(const std::filesystem::path& path);
  void save(const std::filesystem::path& path) const;

  bool empty() const { return words_.empty(); }
  size_t words() const { return words_.size(); }
  int branching() const { return k_; }
  int depth() const { return L_; }

  // levels_up: how far above the words the FeatureVector's nodes sit.
  void transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& features, int levels_up = 2) const;
  WordId wordOf(const uint8_t* descriptor) const;

 private:
  struct Node {
    uint32_t parent = ~0u;
    int32_t word = -1;
    float weight = 0;
    Descriptor descriptor{};
    std::vector<uint32_t> children;
  };
  // Descends to a leaf; `path` receives the nodes visited (root excluded).
  uint32_t descend(const uint8_t* d, std::vector<uint32_t>* path) const;

  int k_ = 0, L_ = 0;
  std::vector<Node> nodes_;       // nodes_[0] is the root
  std::vector<uint32_t> words_;   // word id -> node
};

}  // namespace hiveslam::place
