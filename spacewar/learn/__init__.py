"""Learning: the compiled learning batch (``batch``), the Gymnasium and PettingZoo environments
(``envs``; ``import spacewar.envs`` registers ``Spacewar-v0``), PPO training (``train``) and
the evaluation of a policy file (``evaluate``)."""
