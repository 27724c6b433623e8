#include "io/vocabulary_file.hpp"

#include <cstdlib>

namespace hiveslam::io {

std::filesystem::path vocabularyPath(const core::SlamSettings& settings) {
  if (!settings.vocabulary.empty()) return settings.vocabulary;
  if (const char* env = std::getenv("HIVESLAM_VOCABULARY"); env && *env) return env;
  return std::filesystem::path(HIVESLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l4.bin";
}

std::shared_ptr<const place::Vocabulary> loadVocabulary(const core::SlamSettings& settings) {
  return std::make_shared<const place::Vocabulary>(place::Vocabulary::load(vocabularyPath(settings)));
}

}  // namespace hiveslam::io
