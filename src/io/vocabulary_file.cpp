#include "io/vocabulary_file.hpp"

#include <cstdlib>
#include <string>

#include "common/error.hpp"

namespace hiveslam::io {

std::filesystem::path vocabularyPath(const core::SlamSettings& settings) {
  if (!settings.vocabulary.empty()) return settings.vocabulary;
  if (const char* env = std::getenv("HIVESLAM_VOCABULARY"); env && *env) return env;
  return std::filesystem::path(HIVESLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l4.bin";
}

std::shared_ptr<const place::Vocabulary> loadVocabulary(const core::SlamSettings& settings) {
  try {
    return std::make_shared<const place::Vocabulary>(place::Vocabulary::load(vocabularyPath(settings)));
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (name one with the 'vocabulary' setting or HIVESLAM_VOCABULARY)");
  }
}

}  // namespace hiveslam::io
