#include "core/place/vocabulary.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <fstream>
#include <random>
#include <set>

#include "common/error.hpp"
#include "core/features/hamming.hpp"

namespace hiveslam::place {

namespace {

using Descriptor = Vocabulary::Descriptor;

int dist(const Descriptor& a, const Descriptor& b) { return features::hamming(a.data(), b.data()); }

// Bitwise majority of the members: the binary analogue of a mean.
Descriptor majority(const std::vector<Descriptor>& all, const std::vector<uint32_t>& members) {
  std::array<int, 256> ones{};
  for (uint32_t m : members)
    for (int bit = 0; bit < 256; ++bit) ones[static_cast<size_t>(bit)] += (all[m][static_cast<size_t>(bit / 8)] >> (bit % 8)) & 1;
  Descriptor c{};
  for (int bit = 0; bit < 256; ++bit)
    if (2 * ones[static_cast<size_t>(bit)] > static_cast<int>(members.size()))
      c[static_cast<size_t>(bit / 8)] |= static_cast<uint8_t>(1u << (bit % 8));
  return c;
}

// k-majority clustering of `members`; returns the non-empty clusters.
std::vector<std::vector<uint32_t>> cluster(const std::vector<Descriptor>& all, const std::vector<uint32_t>& members,
                                           int k, int iterations, std::mt19937_64& rng) {
  std::vector<std::vector<uint32_t>> groups;
  if (static_cast<int>(members.size()) <= k) {
    for (uint32_t m : members) groups.push_back({m});
    return groups;
  }
  // k-means++ seeding: each next centre drawn with probability proportional to d^2.
  std::vector<Descriptor> centres;
  centres.push_back(all[members[std::uniform_int_distribution<size_t>(0, members.size() - 1)(rng)]]);
  std::vector<double> d2(members.size(), std::numeric_limits<double>::max());
  while (static_cast<int>(centres.size()) < k) {
    double total = 0;
    for (size_t i = 0; i < members.size(); ++i) {
      const double d = dist(all[members[i]], centres.back());
      d2[i] = std::min(d2[i], d * d);
      total += d2[i];
    }
    if (total <= 0) break;  // every member equals a centre
    double r = std::uniform_real_distribution<double>(0, total)(rng);
    size_t pick = 0;
    for (; pick + 1 < members.size(); ++pick) {
      r -= d2[pick];
      if (r <= 0) break;
    }
    centres.push_back(all[members[pick]]);
  }
  std::vector<int> assignment(members.size(), -1);
  for (int it = 0; it < iterations; ++it) {
    bool changed = false;
    for (size_t i = 0; i < members.size(); ++i) {
      int best = 0, best_d = 257;
      for (size_t c = 0; c < centres.size(); ++c) {
        const int d = dist(all[members[i]], centres[c]);
        if (d < best_d) {
          best_d = d;
          best = static_cast<int>(c);
        }
      }
      if (assignment[i] != best) changed = true;
      assignment[i] = best;
    }
    groups.assign(centres.size(), {});
    for (size_t i = 0; i < members.size(); ++i) groups[static_cast<size_t>(assignment[i])].push_back(members[i]);
    if (!changed) break;
    for (size_t c = 0; c < centres.size(); ++c)
      if (!groups[c].empty()) centres[c] = majority(all, groups[c]);
  }
  groups.erase(std::remove_if(groups.begin(), groups.end(), [](const auto& g) { return g.empty(); }), groups.end());
  return groups;
}

template <typename T>
void put(std::ofstream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
bool get(std::ifstream& in, T& v) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&v), sizeof(T)));
}

constexpr char kMagic[8] = {'H', 'S', 'V', 'O', 'C', 'A', 'B', '1'};

}  // namespace

Vocabulary Vocabulary::train(const std::vector<cv::Mat>& images, const VocabularyOptions& options) {
  Vocabulary v;
  v.k_ = options.branching;
  v.L_ = options.depth;
  std::vector<Descriptor> all;
  for (const cv::Mat& m : images)
    for (int r = 0; r < m.rows; ++r) {
      Descriptor d;
      std::memcpy(d.data(), m.ptr<uint8_t>(r), 32);
      all.push_back(d);
    }
  if (all.empty()) throw InputError("vocabulary training: no descriptors");
  std::mt19937_64 rng(options.seed);
  v.nodes_.emplace_back();
  struct Pending {
    uint32_t node;
    std::vector<uint32_t> members;
    int level;
  };
  std::deque<Pending> queue;
  std::vector<uint32_t> everyone(all.size());
  for (uint32_t i = 0; i < everyone.size(); ++i) everyone[i] = i;
  queue.push_back({0, std::move(everyone), 0});
  // Breadth first, so that a node's children are contiguous and the file order is the tree's.
  while (!queue.empty()) {
    Pending p = std::move(queue.front());
    queue.pop_front();
    const bool leaf = p.level == v.L_ || (p.level > 0 && p.members.size() <= 1);
    if (leaf) {
      v.nodes_[p.node].word = static_cast<int32_t>(v.words_.size());
      v.words_.push_back(p.node);
      continue;
    }
    for (auto& group : cluster(all, p.members, v.k_, options.iterations, rng)) {
      Node child;
      child.parent = p.node;
      child.descriptor = majority(all, group);
      const auto id = static_cast<uint32_t>(v.nodes_.size());
      v.nodes_.push_back(child);
      v.nodes_[p.node].children.push_back(id);
      queue.push_back({id, std::move(group), p.level + 1});
    }
  }
  // IDF: words seen in few images are the distinctive ones.
  std::vector<int> images_with(v.words_.size(), 0);
  for (const cv::Mat& m : images) {
    std::set<WordId> seen;
    for (int r = 0; r < m.rows; ++r) seen.insert(v.wordOf(m.ptr<uint8_t>(r)));
    for (WordId w : seen) ++images_with[w];
  }
  for (size_t w = 0; w < v.words_.size(); ++w)
    v.nodes_[v.words_[w]].weight = images_with[w] > 0
                                       ? static_cast<float>(std::log(static_cast<double>(images.size()) / images_with[w]))
                                       : 0.f;
  return v;
}

uint32_t Vocabulary::descend(const uint8_t* d, std::vector<uint32_t>* path) const {
  uint32_t node = 0;
  while (!nodes_[node].children.empty()) {
    uint32_t best = nodes_[node].children.front();
    int best_d = 257;
    for (uint32_t c : nodes_[node].children) {
      const int h = features::hamming(d, nodes_[c].descriptor.data());
      if (h < best_d) {
        best_d = h;
        best = c;
      }
    }
    node = best;
    if (path) path->push_back(node);
  }
  return node;
}

WordId Vocabulary::wordOf(const uint8_t* descriptor) const {
  return static_cast<WordId>(nodes_[descend(descriptor, nullptr)].word);
}

void Vocabulary::transform(const cv::Mat& descriptors, BowVector& bow, FeatureVector& features, int levels_up) const {
  bow.clear();
  features.clear();
  if (empty()) return;
  std::vector<uint32_t> path;
  for (int r = 0; r < descriptors.rows; ++r) {
    path.clear();
    const uint32_t leaf = descend(descriptors.ptr<uint8_t>(r), &path);
    const Node& n = nodes_[leaf];
    if (n.weight > 0) bow[static_cast<WordId>(n.word)] += n.weight;
    const int level = std::max(1, static_cast<int>(path.size()) - levels_up);
    features[path[static_cast<size_t>(level - 1)]].push_back(r);
  }
  double sum = 0;
  for (const auto& [w, x] : bow) sum += x;
  if (sum > 0)
    for (auto& [w, x] : bow) x /= sum;
}

void Vocabulary::save(const std::filesystem::path& path) const {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError("cannot write vocabulary " + path.string());
  out.write(kMagic, sizeof(kMagic));
  put(out, static_cast<uint32_t>(k_));
  put(out, static_cast<uint32_t>(L_));
  put(out, static_cast<uint32_t>(nodes_.size()));
  for (const Node& n : nodes_) {
    put(out, n.parent);
    put(out, n.word);
    put(out, n.weight);
    out.write(reinterpret_cast<const char*>(n.descriptor.data()), 32);
  }
  if (!out) throw InputError("cannot write vocabulary " + path.string());
}

Vocabulary Vocabulary::load(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open vocabulary " + path.string());
  char magic[8];
  if (!in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0)
    throw InputError("not a hiveslam vocabulary (version 1): " + path.string());
  Vocabulary v;
  uint32_t k = 0, L = 0, count = 0;
  if (!get(in, k) || !get(in, L) || !get(in, count) || k < 2 || k > 64 || L < 1 || L > 10 || count == 0 ||
      count > 50'000'000)
    throw InputError("corrupt vocabulary header: " + path.string());
  v.k_ = static_cast<int>(k);
  v.L_ = static_cast<int>(L);
  v.nodes_.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    Node& n = v.nodes_[i];
    if (!get(in, n.parent) || !get(in, n.word) || !get(in, n.weight) ||
        !in.read(reinterpret_cast<char*>(n.descriptor.data()), 32))
      throw InputError("truncated vocabulary: " + path.string());
    if (i == 0 ? n.parent != ~0u : n.parent >= i) throw InputError("corrupt vocabulary tree: " + path.string());
    if (i > 0) v.nodes_[n.parent].children.push_back(i);
  }
  for (uint32_t i = 0; i < count; ++i) {
    const Node& n = v.nodes_[i];
    if (n.children.empty() != (n.word >= 0) || (n.word >= 0 && static_cast<size_t>(n.word) != v.words_.size()))
      throw InputError("corrupt vocabulary words: " + path.string());
    if (n.word >= 0) v.words_.push_back(i);
  }
  return v;
}

}  // namespace hiveslam::place
