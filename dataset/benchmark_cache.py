"""The built-in default benchmark, made once into a cache, and where a benchmark's results go.

``python -m metrics.compare`` and the 2D baselines' commands (``python -m baselines.wwr2dss``)
run on the default when given no ``--data``, and all of them keep the results of a benchmark
``<data>`` in ``<data>-results`` (:func:`default_results_folder`), so that what one writes the
other reads.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

DEFAULT_CACHE = Path(".cache/envelope-bench")


@dataclass(frozen=True)
class DefaultBenchmark:
    """The default run's benchmark (preset, image size, views, generator workers);
    ``expected_minutes`` is the measured wall time of the whole default run on 2 cores.
    Each method's settings in this run are its own (``Method.short_run``).

    ``root / preset`` is the benchmark folder (relative to the working folder).
    """

    preset: str = "tiny"
    root: Path = DEFAULT_CACHE
    resolution: int = 128
    views: int = 40
    workers: int = 2
    expected_minutes: float = 4.5

    @property
    def folder(self) -> Path:
        return self.root / self.preset

    def announce(self, methods: tuple[str, ...], steps: Mapping[str, int],
                 comparisons: int = 1, inputs: str = "clean and degraded inputs") -> str:
        """The line printed before the default run starts: ``steps``, the training steps
        per building of the methods that train; ``comparisons`` > 1 for a study that
        repeats the default comparison (with every method) that many times, on ``inputs``."""
        made = "cached" if self.folder.is_dir() else "to be generated"
        repeated = (f", {comparisons} comparisons ({inputs})"
                    if comparisons > 1 else "")
        return (
            f"Built-in default: the '{self.preset}' benchmark ({made} in {self.folder}, "
            f"{self.resolution} px, {self.views} orbit views), methods {', '.join(methods)}"
            + "".join(f", {name} {n} training steps per building" for name, n in steps.items())
            + f"{repeated}. This takes up to about {self.expected_minutes * comparisons:g} "
            f"minutes on 2 CPU cores."
        )


RESULTS_SUFFIX = "-results"


def default_results_folder(data: str | Path) -> Path:
    """``<data>-results`` beside ``data`` (a folder of scene folders, or one scene folder),
    ``data`` made absolute: the result files of the methods run on it."""
    data = Path(data).resolve()
    return data.with_name(f"{data.name}{RESULTS_SUFFIX}")


def benchmark_of_results(results: str | Path) -> Path | None:
    """The benchmark folder whose :func:`default_results_folder` is ``results`` (``<X>`` for
    ``<X>-results``), or ``None`` if ``results`` is not named so."""
    results = Path(results)
    if not results.name.endswith(RESULTS_SUFFIX) or results.name == RESULTS_SUFFIX:
        return None
    return results.with_name(results.name.removesuffix(RESULTS_SUFFIX))


def ensure_benchmark(benchmark: DefaultBenchmark) -> Path:
    """Generate the benchmark if absent (the generator resumes and skips finished scenes).

    Raises
    ------
    ValueError
        If the generator is not available or fails.
    """
    try:
        from dataset.generate import GenerateConfig, generate_preset
    except ImportError as exc:
        raise ValueError(f"cannot make the default benchmark: {exc}") from exc
    config = GenerateConfig(resolution=benchmark.resolution, views=benchmark.views)
    # The cache folder is ours: a scene made by other code or settings is simply re-rendered.
    generate_preset(benchmark.preset, benchmark.folder, config, workers=benchmark.workers,
                    overwrite=True)
    return benchmark.folder
