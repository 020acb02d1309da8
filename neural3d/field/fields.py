"""The semantic neural SDF: geometry (two backbones), colour, semantics and the sky.

All networks work in the normalised frame (:mod:`neural3d.field.normalisation`).

- SDF network: point -> signed distance and a geometry feature. Backbones:
  ``mlp`` (NeuS: positional encoding, 8 x 256, skip at layer 4, Softplus(100),
  weight normalisation) and ``grid`` (multi-resolution grid + a small decoder).
  Both start as the SDF of a sphere of ``init_radius`` (geometric initialisation).
- Colour network: (point, view direction, normal, feature) -> RGB in [0, 1].
- Semantic head: feature -> class logits (two hidden layers, view-independent).
- Background network: view direction -> RGB of the environment at infinity.
"""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import Tensor, nn
from torch.nn.utils.parametrizations import weight_norm
from torch.profiler import record_function

from neural3d.config import FieldConfig
from neural3d.field.encoding import GridEncoding, GridInput, PositionalInput, positional_encoding

_SOFTPLUS_BETA = 100.0  # NeuS: close to ReLU but smooth, so the SDF has smooth normals
_MAX_LOG_INV_S = math.log(1e4)  # keeps exp() finite; 1e4 is far sharper than any sample spacing


class GeometricMLP(nn.Module):
    """MLP on ``[x, extra]`` initialised so its first output is ``|x| - radius`` (SAL / NeuS).

    ``forward``: "(N, 3 + extra_dim)" -> "(N, out_dim)"; the weights of ``extra``
    start at zero so that only the position shapes the initial sphere.
    """

    def __init__(self, extra_dim: int, hidden: int, layers: int, out_dim: int, *,
                 radius: float, skip: int | None, normalise_weights: bool) -> None:
        super().__init__()
        d_in = 3 + extra_dim
        if skip is not None and not (0 < skip <= layers and hidden > d_in):
            raise ValueError(f"skip connection at layer {skip} needs 0 < skip <= {layers} layers "
                             f"and hidden width > input width {d_in}, got hidden {hidden}")
        dims = [d_in] + [hidden] * layers + [out_dim]
        self.skip = skip
        self.d_in = d_in
        self.linears = nn.ModuleList()
        for i in range(len(dims) - 1):
            d_out = dims[i + 1] - d_in if skip is not None and i + 1 == skip else dims[i + 1]
            lin = nn.Linear(dims[i], d_out)
            _geometric_init(lin, i, len(dims) - 1, d_in, radius, is_skip=(i == skip))
            self.linears.append(weight_norm(lin) if normalise_weights else lin)
        self.act = nn.Softplus(beta=_SOFTPLUS_BETA)

    def forward(self, inputs: Tensor) -> Tensor:
        h = inputs
        for i, lin in enumerate(self.linears):
            if i == self.skip:
                h = torch.cat([h, inputs], dim=-1) / math.sqrt(2)
            h = lin(h)
            if i < len(self.linears) - 1:
                h = self.act(h)
        return h


def _geometric_init(lin: nn.Linear, i: int, n: int, d_in: int, radius: float,
                    *, is_skip: bool) -> None:
    out_dim, in_dim = lin.weight.shape
    with torch.no_grad():
        if i == n - 1:
            nn.init.normal_(lin.weight, mean=math.sqrt(math.pi) / math.sqrt(in_dim), std=1e-4)
            nn.init.constant_(lin.bias, -radius)
            return
        nn.init.normal_(lin.weight, 0.0, math.sqrt(2) / math.sqrt(out_dim))
        nn.init.zeros_(lin.bias)
        if i == 0:
            lin.weight[:, 3:] = 0.0
        elif is_skip:
            lin.weight[:, -(d_in - 3):] = 0.0


def sdf_backbone(config: FieldConfig, box_min: np.ndarray, box_max: np.ndarray
                 ) -> tuple[PositionalInput | GridInput, GeometricMLP]:
    """The SDF network's input encoding and decoder for ``config.backbone`` (chosen here only).

    ``mlp``: positional encoding + the paper's deep MLP with a skip and weight
    normalisation; ``grid``: multi-resolution grid over the box "(3,)" + a small
    decoder. Both encodings map "(N, 3)" -> "(N, out_dim)" with x first and have
    ``set_step(step)``.
    """
    out_dim = 1 + config.feature_dim
    if config.backbone == "mlp":
        encoding = PositionalInput(config.mlp_frequencies)
        return encoding, GeometricMLP(
            encoding.out_dim - 3, config.mlp_hidden, config.mlp_layers, out_dim,
            radius=config.init_radius, skip=config.mlp_skip, normalise_weights=True)
    if config.backbone == "grid":
        grid = GridEncoding(box_min, box_max, levels=config.grid_levels,
                            features=config.grid_features, min_res=config.grid_min_res,
                            max_res=config.grid_max_res, log2_table=config.grid_log2_table)
        encoding = GridInput(grid, start_levels=config.grid_start_levels,
                             ramp_steps=config.grid_coarse_to_fine_steps)
        return encoding, GeometricMLP(
            encoding.out_dim - 3, config.grid_hidden, 2, out_dim, radius=config.init_radius,
            skip=None, normalise_weights=False)
    raise ValueError(f"unknown backbone {config.backbone!r}; use 'mlp' or 'grid'")


class SDFNetwork(nn.Module):
    """Point "(N, 3)" -> (signed distance "(N,)", geometry feature "(N, F)"), normalised frame."""

    def __init__(self, config: FieldConfig, box_min: np.ndarray, box_max: np.ndarray) -> None:
        super().__init__()
        self.encoding, self.mlp = sdf_backbone(config, box_min, box_max)
        self._calibrate_sphere(config.init_radius)

    @torch.no_grad()
    def _calibrate_sphere(self, radius: float) -> None:
        # A finite-width geometric init gives roughly a*|x| + b (here a ~ 0.75): fit a and b
        # by least squares and fold them into the last layer,
        # so that training starts from the sphere of the configured radius.
        gen = torch.Generator().manual_seed(0)
        x = torch.randn(4096, 3, generator=gen)
        # On a shell around the radius: the zero level set is what must come out right.
        x = x / x.norm(dim=1, keepdim=True) * radius * (0.5 + torch.rand(4096, 1, generator=gen))
        raw = self(x)[0].double()
        target = x.norm(dim=1).double() - radius
        # Closed-form simple linear regression rather than torch.linalg.lstsq: LAPACK's
        # result depends on the memory alignment of its inputs, which made identical
        # runs start from fields a few ulps apart (and so not bit-reproducible).
        raw_c = raw - raw.mean()
        a = float((raw_c * (target - target.mean())).sum() / (raw_c * raw_c).sum())
        b = float(target.mean() - a * raw.mean())
        last = self.mlp.linears[-1]
        if hasattr(last, "parametrizations"):
            last.parametrizations.weight.original0[0] *= a
        else:
            last.weight[0] *= a
        last.bias[0] = a * last.bias[0] + b

    def forward(self, x: Tensor) -> tuple[Tensor, Tensor]:
        features = self.encoding(x)
        with record_function("neural3d.sdf mlp"):
            h = self.mlp(features)
        return h[:, 0], h[:, 1:]


class ColourNetwork(nn.Module):
    """(x "(N, 3)", view dir "(N, 3)", normal "(N, 3)", feature "(N, F)") -> RGB "(N, 3)"."""

    def __init__(self, config: FieldConfig) -> None:
        super().__init__()
        self.frequencies = config.view_frequencies
        d_in = 3 + 3 * (1 + 2 * config.view_frequencies) + 3 + config.feature_dim
        self.net = _relu_mlp(d_in, config.colour_hidden, config.colour_layers, 3)

    def forward(self, x: Tensor, view_dirs: Tensor, normals: Tensor, feature: Tensor) -> Tensor:
        d = positional_encoding(view_dirs, self.frequencies)
        return torch.sigmoid(self.net(torch.cat([x, d, normals, feature], dim=-1)))


class SemanticSDF(nn.Module):
    """All networks of the semantic SDF plus the learnt NeuS sharpness ``inv_s``.

    ``box_min``, ``box_max``: (3,) scene box in the normalised frame (for the grid).
    """

    def __init__(self, config: FieldConfig, num_classes: int, box_min: np.ndarray,
                 box_max: np.ndarray) -> None:
        super().__init__()
        if num_classes < 2:
            raise ValueError(f"need at least 2 semantic classes (background + one), got "
                             f"{num_classes}")
        self.config = config
        self.num_classes = num_classes
        self.sdf_net = SDFNetwork(config, box_min, box_max)
        self.colour_net = ColourNetwork(config)
        self.semantic_net = _relu_mlp(config.feature_dim, config.semantic_hidden, 2, num_classes)
        self.background_net = _relu_mlp(3 * (1 + 2 * config.view_frequencies),
                                        config.background_hidden, 2, 3)
        self.log_inv_s = nn.Parameter(torch.tensor(math.log(config.init_inv_s)))

    def inv_s(self) -> Tensor:
        """NeuS inverse standard deviation of the logistic density (scalar tensor)."""
        return self.log_inv_s.clamp(max=_MAX_LOG_INV_S).exp()

    def set_step(self, step: int) -> None:
        """The encoding's schedule at ``step`` (coarse to fine for ``grid``)."""
        self.sdf_net.encoding.set_step(step)

    def sdf(self, x: Tensor) -> Tensor:
        """"(N, 3)" -> "(N,)" signed distance in normalised units."""
        return self.sdf_net(x)[0]

    def sdf_feature_gradient(self, x: Tensor, *, create_graph: bool
                             ) -> tuple[Tensor, Tensor, Tensor]:
        """SDF "(N,)", feature "(N, F)" and SDF gradient "(N, 3)" at points "(N, 3)".

        ``create_graph``: keep the gradient differentiable (for the eikonal term).
        """
        if self.config.normals == "finite_difference":
            sdf, feature = self.sdf_net(x)
            h = self.config.fd_step
            offsets = torch.eye(3, dtype=x.dtype, device=x.device) * h
            xs = torch.cat([x[:, None] + offsets, x[:, None] - offsets], 1).reshape(-1, 3)
            with record_function("neural3d.sdf gradient"):
                s = self.sdf_net(xs)[0].reshape(len(x), 2, 3)
            return sdf, feature, (s[:, 0] - s[:, 1]) / (2 * h)
        with torch.enable_grad():
            x = x.detach().requires_grad_(True) if not x.requires_grad else x
            sdf, feature = self.sdf_net(x)
            with record_function("neural3d.sdf gradient"):
                (grad,) = torch.autograd.grad(sdf, x, torch.ones_like(sdf),
                                              create_graph=create_graph)
        if not create_graph:
            sdf, feature = sdf.detach(), feature.detach()
        return sdf, feature, grad

    def colour(self, x: Tensor, view_dirs: Tensor, normals: Tensor, feature: Tensor) -> Tensor:
        """RGB "(N, 3)" in [0, 1]; ``view_dirs`` are unit ray directions "(N, 3)"."""
        with record_function("neural3d.colour"):
            return self.colour_net(x, view_dirs, normals, feature)

    def semantic_logits(self, feature: Tensor) -> Tensor:
        """Feature "(N, F)" -> class logits "(N, C)"."""
        with record_function("neural3d.semantic head"):
            return self.semantic_net(feature)

    def background_rgb(self, view_dirs: Tensor) -> Tensor:
        """RGB "(R, 3)" of the environment at infinity seen along unit directions "(R, 3)"."""
        return torch.sigmoid(
            self.background_net(positional_encoding(view_dirs, self.config.view_frequencies))
        )


def _relu_mlp(d_in: int, hidden: int, layers: int, d_out: int) -> nn.Sequential:
    mods: list[nn.Module] = []
    d = d_in
    for _ in range(layers):
        mods += [nn.Linear(d, hidden), nn.ReLU()]
        d = hidden
    mods.append(nn.Linear(d, d_out))
    return nn.Sequential(*mods)
