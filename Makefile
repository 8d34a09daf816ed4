# snowprint: `make demo` runs the demo, `make test` runs every check CI runs.
CARGO ?= cargo
OUT ?= out

.PHONY: demo test lint bench vulkan build

vulkan:
	@scripts/ensure-vulkan.sh

build:
	$(CARGO) build --release --locked -p snowprint-cli

demo: vulkan build
	./target/release/snowprint demo --out $(OUT)

lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --release --locked --workspace --all-targets -- -D warnings

test: vulkan lint
	$(CARGO) test --release --locked --workspace

bench: vulkan build
	./target/release/snowprint bench
