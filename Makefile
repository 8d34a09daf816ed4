# snowprint: `make demo` runs the demo, `make test` runs every check CI runs.
CARGO ?= cargo
OUT ?= out

.PHONY: demo test lint bench vulkan xvfb build play

vulkan:
	@scripts/ensure-vulkan.sh

# An X server without a screen, for the test that opens a real window (tests/play.rs).
xvfb:
	@scripts/ensure-xvfb.sh

build:
	$(CARGO) build --release --locked -p snowprint-cli

demo: vulkan build
	./target/release/snowprint demo --out $(OUT)

lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --release --locked --workspace --all-targets -- -D warnings

test: vulkan xvfb lint
	$(CARGO) test --release --locked --workspace

play: vulkan build
	./target/release/snowprint play

bench: vulkan build
	./target/release/snowprint bench
