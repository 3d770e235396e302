# Multi-stage build: compile in the Rust image, run from a small Debian image as a non-root user.
FROM rust:1-bookworm AS build
WORKDIR /src
COPY . .
RUN cargo build --release --locked --bin crush && strip target/release/crush

FROM debian:bookworm-slim
RUN apt-get update \
    && apt-get install -y --no-install-recommends ca-certificates curl fonts-dejavu-core \
    && rm -rf /var/lib/apt/lists/* \
    && useradd --system --uid 10001 --home-dir /data --create-home crush
COPY --from=build /src/target/release/crush /usr/local/bin/crush
USER crush
WORKDIR /data
# Every interface of the container: `crush serve` then needs a token file (CRUSH_TOKEN_FILE), or
# CRUSH_ALLOW_ANONYMOUS_REMOTE=true with the port published on the host's loopback (README, Docker).
ENV CRUSH_HOST=0.0.0.0 \
    CRUSH_PORT=8080 \
    DATABASE_URL=sqlite:///data/crush.db
VOLUME ["/data"]
EXPOSE 8080
HEALTHCHECK --interval=30s --timeout=3s --start-period=5s --retries=3 \
    CMD curl -fsS http://127.0.0.1:8080/healthz || exit 1
# exec form: the server gets SIGTERM itself and requeues what it was running.
ENTRYPOINT ["crush"]
CMD ["serve"]
