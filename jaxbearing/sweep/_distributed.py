"""Several processes and machines: `jax.distributed` set-up from arguments or environment."""

from __future__ import annotations

import os

from .._errors import UserInputError


def initialize_distributed(
    coordinator: str | None, num_processes: int | None, process_id: int | None
) -> tuple[int, int]:
    """`jax.distributed.initialize` from explicit values or the environment variables
    JAXBEARING_COORDINATOR, JAXBEARING_NUM_PROCESSES, JAXBEARING_PROCESS_ID. Returns
    (process_id, num_processes); (0, 1) without a coordinator. Must run before JAX computes."""
    coordinator = coordinator or os.environ.get("JAXBEARING_COORDINATOR")
    if num_processes is None and "JAXBEARING_NUM_PROCESSES" in os.environ:
        num_processes = _env_int("JAXBEARING_NUM_PROCESSES")
    if process_id is None and "JAXBEARING_PROCESS_ID" in os.environ:
        process_id = _env_int("JAXBEARING_PROCESS_ID")
    if not coordinator:
        if (num_processes or 1) > 1:
            raise UserInputError(
                "--num-processes > 1 needs --coordinator HOST:PORT (or JAXBEARING_COORDINATOR)"
            )
        return 0, 1
    if num_processes is None or process_id is None:
        raise UserInputError(
            "--coordinator needs --num-processes and --process-id (or "
            "JAXBEARING_NUM_PROCESSES and JAXBEARING_PROCESS_ID)"
        )
    if num_processes < 1 or not 0 <= process_id < num_processes:
        raise UserInputError(f"--process-id {process_id} must be in [0, --num-processes {num_processes})")
    import jax

    try:
        jax.distributed.initialize(
            coordinator_address=coordinator, num_processes=num_processes, process_id=process_id
        )
    except RuntimeError as exc:  # JAX refuses once a backend exists
        if "before" not in str(exc) and "already" not in str(exc):
            raise
        raise UserInputError(
            "jax.distributed must be initialised before JAX computes anything: "
            f"start the distributed sweep in a fresh process ({exc})"
        ) from None
    return jax.process_index(), jax.process_count()


def _env_int(name: str) -> int:
    try:
        return int(os.environ[name])
    except ValueError:
        raise UserInputError(f"{name}={os.environ[name]!r} is not an integer") from None
