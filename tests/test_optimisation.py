"""CosineAdam, the optimiser every training loop shares: the same steps as
torch's Adam with a cosine schedule called by hand, so seeded runs reproduce."""

import pytest

torch = pytest.importorskip("torch")
pytestmark = pytest.mark.torch

from autorig_addon.training.nn.optimisation import WEIGHT_DECAY, CosineAdam  # noqa: E402

STEPS = 5
LEARNING_RATE = 0.1


def _model() -> torch.nn.Linear:
    torch.manual_seed(0)
    return torch.nn.Linear(3, 1)


def _loss(model: torch.nn.Linear, step: int) -> torch.Tensor:
    x = torch.arange(3, dtype=torch.float32) + step
    return (model(x) - 1.0).pow(2).sum()


def test_cosine_adam_takes_the_steps_of_adam_and_a_cosine_schedule_called_by_hand():
    shared, by_hand = _model(), _model()
    optimiser = CosineAdam(shared.parameters(), LEARNING_RATE, STEPS)
    adam = torch.optim.Adam(by_hand.parameters(), lr=LEARNING_RATE, weight_decay=WEIGHT_DECAY)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(adam, T_max=STEPS)
    for step in range(STEPS):
        optimiser.step(_loss(shared, step))
        adam.zero_grad()
        _loss(by_hand, step).backward()
        adam.step()
        schedule.step()
    for ours, theirs in zip(shared.parameters(), by_hand.parameters()):
        assert torch.equal(ours, theirs)
    # After T_max steps the cosine has brought the learning rate down to zero.
    assert optimiser.optimiser.param_groups[0]["lr"] == pytest.approx(0.0, abs=1e-12)
