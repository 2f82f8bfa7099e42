"""Running a stranger's bot: its own process, confined by the operating system (``confinement``,
``landlock``), speaking the binary wire (``bothost`` is that process's program), with budgets
(``limits``), its scratch and compiled-code directories (``provision``), and the match side's
seats that start, feed and kill it (``process``); ``probe`` is ``spacewar sandbox``'s bot
that tries each escape and reports what held."""
