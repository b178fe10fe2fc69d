"""The spiral methods over an ARX model: the paper's population searches and
differential evolution (``population``), ``method="spiral"``
(``recommended``) with its spiral over the modes and the numerator projected
out (``projected``), and what it does after the search: the choice among
minima on held-back data (``heldback``), keeping or lifting the default
margin (``margin_choice``), pole-zero cancellation (``cancellation``) and
acting on the modes table (``spurious``)."""
