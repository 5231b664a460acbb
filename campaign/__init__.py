"""Monte-Carlo campaigns on Ray (``campaign.runner``) and what runs on it: the detection
and estimation curves against theory (``campaign.curves``, docs/curves.md)."""
