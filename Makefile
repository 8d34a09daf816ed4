# snowprint: `make demo` runs the demo, `make test` runs every check CI runs.
CARGO ?= cargo
OUT ?= out

# The Bevy plugin (crates/bevy_snowprint) is a workspace of its own on the toolchain Bevy 0.20
# needs, built in target/bevy: scripts/bevy-cargo.sh picks the toolchain and the folder.
BEVY_CARGO ?= scripts/bevy-cargo.sh

.PHONY: demo test lint bench vulkan xvfb build play walk

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
	$(CARGO) fmt --manifest-path crates/bevy_snowprint/Cargo.toml --check
	$(BEVY_CARGO) clippy --release --locked --all-targets -- -D warnings

test: vulkan xvfb lint
	$(CARGO) test --release --locked --workspace
	$(BEVY_CARGO) test --release --locked

play: vulkan build
	./target/release/snowprint play

bench: vulkan build
	./target/release/snowprint bench

# Walk through snow in Bevy (crates/bevy_snowprint/examples/walk.rs): WASD.
walk: vulkan
	$(BEVY_CARGO) run --release --locked --example walk
