# The two commands of the README:
#   make demo   set up, build, run the main job on a built-in default
#   make test   set up, build, run every test
# Without set-up (packages already installed): make build, make check, make asan, make tsan.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: setup build demo test check asan tsan fuzz bench clean

setup:
	bash scripts/setup

build:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j $(JOBS)

demo: setup build
	./$(BUILD)/apps/hiveslam demo --out demo_out

test: setup check fuzz

check: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# Debian's Fast DDS 2.9 deletes its DataReaders with a mismatched sized delete (its own code,
# seen at every node's shutdown); the check is off so that reports mean ours.
asan:
	ASAN_OPTIONS=new_delete_type_mismatch=0 $(MAKE) check BUILD=build-asan CMAKE_FLAGS="-DHIVESLAM_ASAN=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHIVESLAM_BUILD_BENCH=OFF"

tsan:
	$(MAKE) check BUILD=build-tsan CMAKE_FLAGS="-DHIVESLAM_TSAN=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHIVESLAM_BUILD_BENCH=OFF"

# The libFuzzer targets, FUZZ_SECONDS each (fuzz/, built with clang in build-fuzz); `make test`
# runs them 5 s each (a fresh-clone CI run took 30 min with 10).
FUZZ_SECONDS ?= 5
fuzz:
	bash scripts/fuzz $(FUZZ_SECONDS)

bench: build
	./$(BUILD)/bench/render_bench

clean:
	rm -rf build build-asan build-tsan build-fuzz demo_out
