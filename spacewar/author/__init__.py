"""Tools for a bot's author: ``spacewar check`` (``check``) and ``spacewar new-bot``
(``new_bot``)."""
