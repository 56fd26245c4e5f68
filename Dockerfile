# chocmodal service image: `docker build -t chocmodal .` then (API + workers on SQLite)
# `docker run -p 8080:8080 -v chocmodal-data:/data -v $PWD/tokens:/etc/chocmodal/tokens:ro \
#      -e CHOCMODAL_AUTH_FILE=/etc/chocmodal/tokens chocmodal`
# The image listens on 0.0.0.0, so it refuses to start without an auth file
# (`<tenant> <token>` lines, see docs/service.md), unless CHOCMODAL_INSECURE=true
# (behind a proxy that authenticates). With PostgreSQL, API and workers apart:
# `docker compose up` (compose.yaml).
FROM rust:1.95-bookworm AS build
WORKDIR /src
COPY Cargo.toml Cargo.lock ./
COPY src src
COPY crates crates
COPY build.rs build.rs
COPY migrations migrations
# The dashboard embeds the shipped examples as templates of its submit page.
COPY examples examples
RUN cargo build --release --locked --bin chocmodal

FROM debian:bookworm-slim
RUN apt-get update \
    && apt-get install -y --no-install-recommends curl ca-certificates \
    && rm -rf /var/lib/apt/lists/* \
    && useradd --system --uid 10001 --home-dir /data chocmodal \
    && mkdir -p /data && chown chocmodal /data
COPY --from=build /src/target/release/chocmodal /usr/local/bin/chocmodal
USER chocmodal
ENV CHOCMODAL_BIND=0.0.0.0:8080 \
    CHOCMODAL_DATA_DIR=/data \
    CHOCMODAL_LOG_FORMAT=json
VOLUME ["/data"]
EXPOSE 8080
HEALTHCHECK --interval=30s --timeout=3s --start-period=10s \
    CMD curl -fsS http://127.0.0.1:8080/healthz || exit 1
# SIGTERM starts a graceful shutdown: give running jobs their grace period.
STOPSIGNAL SIGTERM
ENTRYPOINT ["chocmodal", "serve"]
