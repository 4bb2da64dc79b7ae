# The test image: the same steps as CI (.ci/run) on Debian bookworm with Rust.
#   docker build -t shapecue . && docker run --rm shapecue
FROM rust:1-bookworm
WORKDIR /src
COPY . .
RUN bash scripts/setup.sh && rustup component add rustfmt clippy
RUN cargo fmt --check && cargo clippy --all-targets -- -D warnings && cargo build --release --all-targets
CMD ["cargo", "test", "--release"]
