# The test image: the same steps as CI (.ci/run) on Debian bookworm with Rust,
# on the repository alone (as a user clones it):
#   docker build -t shapecue . && docker run --rm shapecue
# Tests that need the larger shared data sets (real scans, volumes and skinned
# animations; see data/README.md for what is bundled instead) skip with a
# message without them. To run those too, mount the folder that holds them
# (meshes/, volumes/, animations/) and name it:
#   docker run --rm -v /path/to/shared/data:/data:ro -e SHAPECUE_SHARED_DATA=/data shapecue
FROM rust:1-bookworm
WORKDIR /src
COPY . .
RUN bash scripts/setup.sh && rustup component add rustfmt clippy
RUN cargo fmt --check && cargo clippy --all-targets -- -D warnings && cargo build --release --all-targets
CMD ["cargo", "test", "--release"]
