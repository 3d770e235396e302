# Multi-stage build: dependencies compiled in a layer of their own (cargo-chef), so that a change
# to crush's own code rebuilds only crush; the binary runs from a small Debian image as a
# non-root user.
FROM rust:1-bookworm AS chef
RUN cargo install cargo-chef --locked --version ^0.1
WORKDIR /src

# The dependency graph alone (recipe.json changes only when Cargo.toml or Cargo.lock do).
FROM chef AS plan
COPY . .
RUN cargo chef prepare --recipe-path recipe.json

FROM chef AS build
# .cargo/config.toml sets the target CPU: the dependencies must be built with the same flags.
COPY .cargo .cargo
COPY --from=plan /src/recipe.json recipe.json
RUN cargo chef cook --release --locked --recipe-path recipe.json --bin crush
COPY . .
RUN cargo build --release --locked --bin crush && strip target/release/crush

FROM debian:bookworm-slim
# curl for the health check; the plots' font is compiled into the binary.
RUN apt-get update \
    && apt-get install -y --no-install-recommends ca-certificates curl \
    && rm -rf /var/lib/apt/lists/* \
    && useradd --system --uid 10001 --home-dir /data --create-home crush
COPY --from=build /src/target/release/crush /usr/local/bin/crush
USER crush
WORKDIR /data
# Every interface of the container: `crush serve` then needs a token file (CRUSH_TOKEN_FILE), or
# CRUSH_ALLOW_ANONYMOUS_REMOTE=true with the port published on the host's loopback (docs/operations.md, Docker).
ENV CRUSH_HOST=0.0.0.0 \
    CRUSH_PORT=8080 \
    DATABASE_URL=sqlite:///data/crush.db
VOLUME ["/data"]
EXPOSE 8080
HEALTHCHECK --interval=30s --timeout=3s --start-period=5s --retries=3 \
    CMD curl -fsS http://127.0.0.1:8080/healthz || exit 1
# exec form: the server gets SIGTERM itself and requeues what it was running. `docker stop`
# waits 10 s by default; give it more than --shutdown-grace-s plus 30 s to checkpoint
# (`docker stop -t 60`, or compose's stop_grace_period).
STOPSIGNAL SIGTERM
ENTRYPOINT ["crush"]
CMD ["serve"]
