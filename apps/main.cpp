// hiveslam: one program for every node and every tool; see `hiveslam --help`.
#include <glog/logging.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "apps/commands.hpp"
#include "communication/dds/dds_transport.hpp"
#include "common/error.hpp"

int main(int argc, char** argv) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  // Each SLAM module has its own thread; OpenCV's pool on top of them gains little on small
  // images and its workers spin between calls (7% of the tracking process's CPU, measured
  // with perf on the standard suite).
  cv::setNumThreads(1);
  // Ceres logs through glog; its warnings (a rejected LM step) are routine, not for users.
  FLAGS_minloglevel = google::GLOG_ERROR;
  google::InitGoogleLogging(argv[0]);
  // SPDLOG_LEVEL=debug: each packet sent and received, with its topic, kind, map and size.
  spdlog::cfg::load_env_levels();
  CLI::App app{"hiveslam: self-organizing distributed monocular visual SLAM"};
  app.require_subcommand(1);
  app.footer("Example:\n  hiveslam demo                 (render a sequence, run it on 1 and 3 nodes)\n"
             "  hiveslam run DATASET --out DIR\n"
             "Each command: hiveslam COMMAND --help");
  app.set_version_flag("--version", "hiveslam 0.1.0");
  hiveslam::apps::addSynthCommand(app);
  hiveslam::apps::addEvalCommand(app);
  hiveslam::apps::addInfoCommand(app);
  hiveslam::apps::addDemoCommand(app);
  hiveslam::apps::addRunCommand(app);
  hiveslam::apps::addVocabCommand(app);
  hiveslam::apps::addNodeCommand(app);
  hiveslam::apps::addClusterCommand(app);
  hiveslam::apps::addBenchCommand(app);
  hiveslam::apps::addPlayCommand(app);
  hiveslam::apps::addViewCommand(app);
  hiveslam::apps::addTopicsCommand(app);
  hiveslam::apps::addKeysCommand(app);
  int status = 0;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    status = app.exit(e);
  } catch (const hiveslam::InputError& e) {
    std::fprintf(stderr, "hiveslam: error: %s\n", e.what());
    status = 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hiveslam: error: %s\n", e.what());
    status = 1;
  }
  // A DDS teardown left behind deadlocked inside Fast DDS, whose exit handlers would wait on it
  // too: the results are written, so the program ends here, without them.
  if (hiveslam::communication::DdsTransport::teardownsRunning() > 0) {
    spdlog::default_logger()->flush();
    std::fflush(nullptr);
    std::_Exit(status);
  }
  return status;
}
